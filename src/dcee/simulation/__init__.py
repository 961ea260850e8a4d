"""Simulated searches: ground truth and the episode loop."""

from dcee.simulation.episode import EpisodeResult, run_episode, streams
from dcee.simulation.truth import IsotropicTruth, TruthModel, make_truth

__all__ = ["EpisodeResult", "IsotropicTruth", "TruthModel", "make_truth", "run_episode", "streams"]
