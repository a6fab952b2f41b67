#!/usr/bin/env bash
# Regenerates the golden vector set in vectors/ from the embedded default config. Run it only
# when a change to the model, the writers or the default is intended; commit the result. The
# guide's manifest schema is generated from vectors/manifest.json: it is rewritten too.
set -euo pipefail
cd "$(dirname "$0")/.."
GYROFX_UPDATE_GOLDEN=1 cargo test --test main golden::
GYROFX_UPDATE_DOCS=1 cargo test --test main docs::
git status --short vectors/ docs/guide/src/reference/
