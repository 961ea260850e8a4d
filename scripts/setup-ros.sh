#!/usr/bin/env bash
# Create .venv-ros (if needed) and install dcee with ROS 2 (rclpy and the message packages from
# PyPI, no system ROS) and pytest into it. A separate venv because the ROS wheels
# install a .pth bootstrapper that re-executes every Python start in their venv (0.16 s instead
# of 0.05 s). x86-64 Linux, CPython 3.10-3.14 only (what the ROS wheels are built for).
set -euo pipefail
cd "$(dirname "$0")/.."
# scripts/test.sh sets this once both venvs are installed, so that the steps it runs side by
# side do not install into the same source tree at once
if [ "${DCEE_SETUP_DONE:-0}" = 1 ]; then exit 0; fi
source scripts/venv.sh
# the ROS 2 extra and pytest only: the ROS 2 tests (tests/ros) need nothing else, and the rest of
# the development tools live in .venv
install_into .venv-ros -e ".[ros,geo]" "pytest>=8.0"
