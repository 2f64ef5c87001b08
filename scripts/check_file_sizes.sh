#!/usr/bin/env bash
# Fails when a Rust or Python source file of the project is over 800 lines (the house rule:
# small files with one purpose each). Usage: scripts/check_file_sizes.sh [LIMIT]
set -euo pipefail
cd "$(dirname "$0")/.."
limit="${1:-800}"
over=$(git ls-files '*.rs' '*.py' | xargs wc -l | awk -v l="$limit" '$2 != "total" && $1 > l {print "  " $2 ": " $1 " lines"}')
if [ -n "$over" ]; then
  echo "files over $limit lines:" >&2
  echo "$over" >&2
  exit 1
fi
echo "file sizes: every source file within $limit lines"
