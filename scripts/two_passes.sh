#!/usr/bin/env bash
# Two passes, the second driven back: scripts/fusion.sh passes (docs/results.md, "Two passes").
# Usage: [OFFSET=0.1] scripts/two_passes.sh OUT_DIR SCENE:SEED...   (e.g. kawasaki:1)
exec "$(dirname "$0")/fusion.sh" passes "$@"
