"""Bayesian estimation of the source term."""

from dcee.estimation.model_bank import ModelBank
from dcee.estimation.particle_filter import ParticleFilter, UpdateInfo, systematic_resample
from dcee.estimation.priors import Fixed, Gamma, Normal, SourcePrior, Uniform

__all__ = [
    "Fixed",
    "Gamma",
    "ModelBank",
    "Normal",
    "ParticleFilter",
    "SourcePrior",
    "Uniform",
    "UpdateInfo",
    "systematic_resample",
]
