#!/usr/bin/env bash
# Renders every gallery program to docs/gallery/NAME.png with lsyc itself.
# Scenes (files with a `scene`) need their environment and are skipped here.
set -euo pipefail
cd "$(dirname "$0")/../.."
cargo build --release --quiet
for f in lang-examples/*.lsy; do
    grep -q '^scene ' "$f" && continue
    name=$(basename "$f" .lsy)
    ./target/release/lsyc run "$f" -o "docs/gallery/$name.png" --size 480
done
