#!/usr/bin/env bash
# Style and static checks (issue 19): clang-format over every C++ file, then clang-tidy
# (.clang-tidy: bugprone, performance, functions over 80 lines) over the given files or all.
#   scripts/lint.sh                 # everything (clang-tidy takes several minutes on 2 cores)
#   scripts/lint.sh --format-only   # the formatting check alone (seconds)
#   scripts/lint.sh FILE...         # clang-tidy on these files only
# Exit 1 when a check fails, 2 when a tool or the build's compile_commands.json is missing.
set -uo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
cd "$root"
for tool in clang-format clang-tidy; do
    command -v "$tool" >/dev/null || { echo "lint: $tool not found (scripts/setup.sh installs it)" >&2; exit 2; }
done
mapfile -t all < <(git ls-files '*.cpp' '*.h')
status=0
if ! clang-format --dry-run -Werror "${all[@]}"; then
    echo "lint: formatting differs; fix with: clang-format -i \$(git ls-files '*.cpp' '*.h')" >&2
    status=1
fi
[ "${1:-}" = "--format-only" ] && exit $status
[ -f build/compile_commands.json ] || { echo "lint: build/compile_commands.json missing: run scripts/build.sh first" >&2; exit 2; }
if [ $# -gt 0 ]; then files=("$@"); else mapfile -t files < <(git ls-files '*.cpp' ':!tests/data'); fi
out=$(printf '%s\n' "${files[@]}" | xargs -P "$(nproc)" -n 4 clang-tidy -p build --quiet 2>/dev/null)
warnings=$(grep -E ': (warning|error): ' <<<"$out" | sort -u)
if [ -n "$warnings" ]; then
    echo "$warnings"
    echo "lint: $(wc -l <<<"$warnings") clang-tidy finding(s)" >&2
    status=1
fi
exit $status
