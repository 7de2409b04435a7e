#!/usr/bin/env bash
# Fails, listing the files, when a C++ source is not formatted as .clang-format says.
set -euo pipefail
cd "$(dirname "$0")/.."
unformatted=$(find idl runtime bag calibration components tools test bench examples fuzz \( -name '*.cpp' -o -name '*.hpp' -o -name '*.h' \) |
  sort | while read -r file; do
    clang-format --dry-run -Werror "$file" > /dev/null 2>&1 || echo "$file"
  done)
if [ -n "$unformatted" ]; then
  echo "not clang-format clean (run: clang-format -i FILE):"
  echo "$unformatted" | sed 's/^/  /'
  exit 1
fi
