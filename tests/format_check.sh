#!/usr/bin/env bash
# Every tracked C++ source is formatted as .clang-format says
# (clang-format --dry-run -Werror); a file that is not names itself and its line.
set -u
SRC="${DDSWARM_SRC:?DDSWARM_SRC must point at the source tree}"
command -v clang-format >/dev/null || { echo "SKIP: clang-format is not installed (scripts/setup installs it)"; exit 77; }
cd "$SRC"
if git rev-parse --is-inside-work-tree >/dev/null 2>&1; then
  files=$(git ls-files '*.cpp' '*.hpp')
else
  files=$(find . -path ./build -prune -o \( -name '*.cpp' -o -name '*.hpp' \) -print)
fi
out=$(echo "$files" | xargs clang-format --dry-run -Werror 2>&1)
rc=$?
if [ $rc -ne 0 ]; then
  echo "$out" | grep "error:" | head -40
  echo "FAIL: sources not formatted; run: git ls-files '*.cpp' '*.hpp' | xargs clang-format -i"
  exit 1
fi
echo "PASS: $(echo "$files" | wc -l) files formatted"
