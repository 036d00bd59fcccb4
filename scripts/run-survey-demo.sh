#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# The demo survey end to end (docs/study-guide.md): sets everything up, serves web/survey-demo.html on
# http://127.0.0.1:8000 (standing in for the survey site) and starts sim_manager on http://127.0.0.1:8080
# with the tutorial, warehouse and lab, allowing that origin to embed sessions. Ctrl-C stops both.
#   scripts/run-survey-demo.sh [sim_manager options, e.g. --session-arg --time-limit --session-arg 60]
set -euo pipefail
cd "$(dirname "$0")/.."
# Only what the survey demo runs, and sim_report for its data afterwards.
scripts/setup.sh --target sim_manager --target sim_report
survey_port=8000
node scripts/serve-survey-demo.mjs "$survey_port" &
survey_pid=$!
trap 'kill "$survey_pid" 2>/dev/null || true' EXIT
echo "open the survey: http://127.0.0.1:$survey_port/survey-demo.html?manager=http://127.0.0.1:8080"
echo "session data: build/demo-data (then: build/simulator/tools/report/sim_report build/demo-data)"
build/manager/sim_manager --scenarios warehouse,lab,tutorial --allow-repeat true --data-dir build/demo-data \
  --frame-origins "http://127.0.0.1:$survey_port" "$@"
