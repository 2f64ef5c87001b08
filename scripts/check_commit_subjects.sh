#!/usr/bin/env bash
# Fails when a commit subject since the house-keeping baseline is over 100 characters, and
# warns over 72 (the project's rule: a subject of at most 72 characters naming the area,
# `solver: …`, `collide: …`, with figures and reasoning in the body).
#
# Usage: scripts/check_commit_subjects.sh [BASE]
# BASE defaults to e3b109f, the last commit before the rule was checked; commits reachable
# from HEAD and not from BASE are read. Exit 0 when every subject is within 100 characters,
# 1 when one is not, 2 when BASE is not in the history (a shallow clone: fetch more of it).
set -euo pipefail
cd "$(dirname "$0")/.."
base="${1:-e3b109f}"
if ! git rev-parse --quiet --verify "$base^{commit}" >/dev/null; then
  echo "check_commit_subjects: $base is not in this clone's history (shallow clone?)" >&2
  exit 2
fi
limit=100
want=72
bad=0
total=0
while IFS= read -r line; do
  hash="${line%% *}"
  subject="${line#* }"
  total=$((total + 1))
  n=${#subject}
  if [ "$n" -gt "$limit" ]; then
    echo "commit $hash: subject is $n characters (over $limit): $subject" >&2
    bad=$((bad + 1))
  elif [ "$n" -gt "$want" ]; then
    echo "commit $hash: subject is $n characters (aim at $want or fewer)"
  fi
done < <(git log --no-merges --format='%h %s' "$base..HEAD")
if [ "$bad" -gt 0 ]; then
  echo "commit subjects: $bad of $total over $limit characters" >&2
  exit 1
fi
echo "commit subjects: $total checked since $base, none over $limit characters"
