"""Resumable simulation campaigns: many (configuration, repeat, strategy) searches."""

from dcee.campaign.folder import Campaign, SearchTask
from dcee.campaign.runner import run_campaign
from dcee.campaign.suites import SUITES, suite_scenarios

__all__ = ["SUITES", "Campaign", "SearchTask", "run_campaign", "suite_scenarios"]
