#!/usr/bin/env bash
# Set up .venv-ros (scripts/setup-ros.sh) and run the ROS 2 tests (tests/ros) in it over real
# topics. A missing rclpy fails them (DCEE_REQUIRE_ROS=1) instead of skipping. Where this user
# may create a network namespace, the tests run in one that has only the loopback interface, so
# no DDS traffic can leave the machine; elsewhere discovery is limited to localhost.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup-ros.sh
export DCEE_REQUIRE_ROS=1 ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST
RUN=(.venv-ros/bin/python -m pytest -q -p no:cacheprovider -W ignore::DeprecationWarning tests/ros "$@")
if unshare -rn sh -c 'ip link set lo up' 2>/dev/null; then
  unshare -rn sh -c 'ip link set lo up && exec "$@"' sh "${RUN[@]}"
else
  echo "test-ros: no network namespace here; ROS discovery limited to localhost" >&2
  "${RUN[@]}"
fi
