"""Simulated searches: ground truth (isotropic, filament, puffs, playback) and the episode loop."""

from dcee.simulation.episode import EpisodeResult, run_episode, streams
from dcee.simulation.filament import FilamentTruth
from dcee.simulation.playback import PlaybackTruth, load_recording, save_recording
from dcee.simulation.puffs import PuffTruth
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
    "PuffTruth",
    "TruthModel",
    "load_recording",
    "make_truth",
    "plume_stream",
    "run_episode",
    "save_recording",
    "streams",
]
