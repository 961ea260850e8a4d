"""What the sensor sees in a simulated search: the ground-truth plumes (isotropic, filament,
puffs, recorded playback, the lbm solver plume and its 3-D surface-layer sibling lbm3d, a GADEN
simulation),
registered by name. The search that runs against them is :mod:`dcee.runs`."""

from dcee.simulation.filament import FilamentTruth
from dcee.simulation.gaden import GadenTruth
from dcee.simulation.lbm import SolverPlumeTruth
from dcee.simulation.lbm3d import SolverPlume3dTruth
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
    "FilamentTruth",
    "GadenTruth",
    "InjectedTruth",
    "IsotropicTruth",
    "PlaybackTruth",
    "PuffTruth",
    "SolverPlume3dTruth",
    "SolverPlumeTruth",
    "TruthModel",
    "load_recording",
    "make_truth",
    "plume_stream",
    "save_recording",
]
