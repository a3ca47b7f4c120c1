#!/usr/bin/env bash
# Screenshots of the nightly report's findings (issue 26) for reports/screenshots/:
#   nightly_findings_first_screen.png  the first 1440x900 screen: the findings in words
#   nightly_findings.png               the findings section, first 1440xHEIGHT (default 3200): the error
#                                      budget's stacked bars under the sweep images, explore's fronts,
#                                      the accuracy table, the cost bands, what changed since the last run
#
#   scripts/findings_screenshots.sh RESULTS.json HISTORY.jsonl FINDINGS.json... [-- OUT_DIR]
#
# RESULTS.json: a nightly run (`iblcheck run --suite nightly --out DIR --history HISTORY.jsonl`);
# FINDINGS: `iblcheck explain --json` and `iblcheck explore --json` files. Needs build/iblcheck and
# build/tests/report_browser.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${BUILD:-build}
HEIGHT=${HEIGHT:-3200}
[[ $# -ge 3 ]] || { sed -n 2,13p "$0" >&2; exit 2; }
results=$1 history=$2
shift 2
findings=() out=reports/screenshots
while [[ $# -gt 0 ]]; do
  if [[ $1 == -- ]]; then out=$2; break; fi
  findings+=(--findings "$1")
  shift
done
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$BUILD/iblcheck" report "$results" --out "$tmp/report" --history "$history" "${findings[@]}"
"$BUILD/tests/report_browser" "$tmp/report/index.html" --out "$out/nightly_findings_first_screen.png"
"$BUILD/tests/report_browser" "$tmp/report/index.html" --out "$out/nightly_findings.png" --height "$HEIGHT"
