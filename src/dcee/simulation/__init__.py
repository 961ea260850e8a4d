"""Simulated searches: ground truth (isotropic, filament, playback) and the episode loop."""

from dcee.simulation.episode import EpisodeResult, run_episode, streams
from dcee.simulation.filament import FilamentTruth
from dcee.simulation.playback import PlaybackTruth, load_recording, save_recording
from dcee.simulation.truth import (
    InjectedTruth,
    IsotropicTruth,
    TruthModel,
    make_truth,
    plume_stream,
)

__all__ = [
    "EpisodeResult",
    "FilamentTruth",
    "InjectedTruth",
    "IsotropicTruth",
    "PlaybackTruth",
    "TruthModel",
    "load_recording",
    "make_truth",
    "plume_stream",
    "run_episode",
    "save_recording",
    "streams",
]
