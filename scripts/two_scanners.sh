#!/usr/bin/env bash
# Two scanners in an X: scripts/fusion.sh scanners (docs/results.md, "Two scanners").
# Usage: scripts/two_scanners.sh OUT_DIR SCENE:SEED...   (e.g. kawasaki:1 random:1001)
exec "$(dirname "$0")/fusion.sh" scanners "$@"
