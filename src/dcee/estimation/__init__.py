"""Bayesian estimation of the source term: the estimator interface (:mod:`~dcee.estimation.base`),
the particle filter, the bank of filters under competing reading models, priors and resampling."""

from dcee.estimation.base import Estimator, ReadingModelChoice, UpdateInfo
from dcee.estimation.model_bank import ModelBank
from dcee.estimation.particle_filter import ParticleFilter
from dcee.estimation.priors import Fixed, Gamma, Normal, SourcePrior, Uniform
from dcee.estimation.resampling import effective_sample_size, systematic_resample

__all__ = [
    "Estimator",
    "Fixed",
    "Gamma",
    "ModelBank",
    "Normal",
    "ParticleFilter",
    "ReadingModelChoice",
    "SourcePrior",
    "Uniform",
    "UpdateInfo",
    "effective_sample_size",
    "systematic_resample",
]
