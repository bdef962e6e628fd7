#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# What a user reads names no issue numbers: the README, docs/, every README, and the settle
# command's sources (its help, errors and reports are printed from app/) and tools/.
#   no_issue_numbers.sh ROOT
set -u
cd "$1" || exit 1
hits=$(grep -rnEi 'issues?[ #-]*[0-9]+|issues/[0-9]|\(issue' README.md docs app tools \
  --include='*.md' --include='*.cpp' --include='*.hpp' --include='*.py' 2>/dev/null;
  grep -nEi 'issues?[ #-]*[0-9]+|issues/[0-9]|\(issue' tools/* */README.md 2>/dev/null)
if [ -n "$hits" ]; then
  echo "FAIL: issue numbers where users read them:"
  echo "$hits"
  exit 1
fi
echo "ok: no issue numbers in README.md, docs/, the READMEs, app/ or tools/"
