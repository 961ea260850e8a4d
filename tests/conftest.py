"""Shared fixtures."""

from __future__ import annotations

import pytest

from dcee.models.sensor import Sensor


@pytest.fixture
def sensor() -> Sensor:
    return Sensor.paper_exact()
