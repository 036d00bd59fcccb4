#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# Sets everything up and starts the demo: sim_rfb in the warehouse scenario, printing the link to open.
#   scripts/run-demo.sh [sim_rfb options, e.g. --port 5901 --bind 0.0.0.0 --scenario lab]
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
exec build/simulator/sim_rfb --scenario warehouse "$@"
