#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# Sets everything up and starts the demo: sim_manager on http://127.0.0.1:8080/ with the shipped scenarios,
# printing a participant link to open. Each link (uid) gets its own sim_rfb session.
#   scripts/run-demo.sh [sim_manager options, e.g. --port 9000 --listen-address 0.0.0.0 --max-sessions 2]
set -euo pipefail
cd "$(dirname "$0")/.."
# Only what the demo runs: sim_manager, and with it sim_rfb, the page and the x11 launcher (no tests).
scripts/setup.sh --target sim_manager
# The demo lets a link be opened again after its session ended; a study leaves allow_repeat off.
exec build/manager/sim_manager --scenarios warehouse,lab,tutorial --allow-repeat true --data-dir build/demo-data "$@"
