#!/bin/sh
# Re-derives @folder@/stat.json@report@: run from place_and_route/<block>/.
set -e
@yosys@ -q -l @folder@/yosys.log -s @folder@/synth.ys
