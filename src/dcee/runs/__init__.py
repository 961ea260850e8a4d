"""A search run, one module per job: assemble it from a configuration (:mod:`~dcee.runs.assemble`),
its random streams (:mod:`~dcee.runs.streams`), step it (:mod:`~dcee.runs.simulation`), fly it
with a planner (:mod:`~dcee.runs.episode`), record it (:mod:`~dcee.runs.records`), score it
(:mod:`~dcee.runs.metrics`), the result and its folder (:mod:`~dcee.runs.result`,
:mod:`~dcee.runs.folder`) and its identity (:mod:`~dcee.runs.identity`). The truths it runs
against live in :mod:`dcee.simulation`; campaigns of runs in :mod:`dcee.campaign`."""

from dcee.runs.assemble import make_searcher, planner_defaults
from dcee.runs.episode import run_episode
from dcee.runs.identity import scenario_identity, scenario_key
from dcee.runs.metrics import longest_stall, search_stall, search_summary, summarise
from dcee.runs.records import reading_record
from dcee.runs.result import (
    FINAL_SAMPLE,
    RESULT_FILES,
    SNAPSHOT_FRACTIONS,
    EpisodeResult,
    snapshot_times,
)
from dcee.runs.simulation import SearchSimulation
from dcee.runs.streams import MOTION_STREAM, motion_stream, streams

__all__ = [
    "FINAL_SAMPLE",
    "MOTION_STREAM",
    "RESULT_FILES",
    "SNAPSHOT_FRACTIONS",
    "EpisodeResult",
    "SearchSimulation",
    "longest_stall",
    "make_searcher",
    "motion_stream",
    "planner_defaults",
    "reading_record",
    "run_episode",
    "scenario_identity",
    "scenario_key",
    "search_stall",
    "search_summary",
    "snapshot_times",
    "streams",
    "summarise",
]
