"""Bayesian estimation of the source term."""

from dcee.estimation.particle_filter import ParticleFilter, UpdateInfo, systematic_resample
from dcee.estimation.priors import Fixed, Gamma, Normal, SourcePrior, Uniform

__all__ = [
    "Fixed",
    "Gamma",
    "Normal",
    "ParticleFilter",
    "SourcePrior",
    "Uniform",
    "UpdateInfo",
    "systematic_resample",
]
