#!/usr/bin/env bash
# Renders every gallery program to docs/gallery/NAME.png with lsyc itself.
# Scenes (files with a `scene`) are drawn with their guides' outlines.
set -euo pipefail
cd "$(dirname "$0")/../.."
cargo build --release --quiet
for f in lang-examples/*.lsy; do
    name=$(basename "$f" .lsy)
    extra=()
    grep -q '^scene ' "$f" && extra=(--guides)
    ./target/release/lsyc run "$f" -o "docs/gallery/$name.png" --size 480 "${extra[@]}"
done
