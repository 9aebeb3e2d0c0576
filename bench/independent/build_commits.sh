#!/bin/bash
# Build pyspline at each commit the claims compare, one worktree + venv per commit.
# usage: bench/independent/build_commits.sh COMMIT...   (worktree /work/wt/ic34_C, venv /work/venv/ic34_C)
set -e
SUN=/root/.cache/pyspline/sundials-6.4.1+dfsg1-3-O3-arkode
for c in "$@"; do
  wt=/work/wt/ic34_$c; venv=/work/venv/ic34_$c
  [ -d "$wt" ] || git -C /work/main worktree add --detach "$wt" "$c"
  [ -d "$venv" ] || python3 -m venv --system-site-packages "$venv"
  ( source "$venv/bin/activate" && cd "$wt" && \
    pip install -q --no-build-isolation --no-deps -Csetup-args=-Dsundials_prefix=$SUN \
        -Cbuild-dir=build/pip . ) && echo "built $c" || echo "FAILED $c"
done
