#!/usr/bin/env bash
# Renders every gallery program to docs/gallery/NAME.png with lsyc itself.
# Scenes (files with a `scene`) are drawn with their guides' outlines; a file's
# first scene is NAME.png, each further scene NAME-SCENE.png (lower case).
# Edited scenes (Guided Procedural Modeling, Figs. 1, 4 and 9b) are edited with
# `lsyc edit` into a temporary file and drawn to NAME-edited.png.
set -euo pipefail
cd "$(dirname "$0")/../.."
cargo build --release --quiet
lsyc=./target/release/lsyc
for f in lang-examples/*.lsy; do
    name=$(basename "$f" .lsy)
    extra=()
    grep -q '^scene ' "$f" && extra=(--guides)
    "$lsyc" run "$f" -o "docs/gallery/$name.png" --size 480 "${extra[@]}"
    for scene in $(grep '^scene ' "$f" | tail -n +2 | cut -d' ' -f2); do
        lower=$(echo "$scene" | tr '[:upper:]' '[:lower:]')
        "$lsyc" run "$f" --scene "$scene" -o "docs/gallery/$name-$lower.png" --size 480 --guides
    done
done

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
edited() {
    local name=$1
    shift
    "$lsyc" edit "lang-examples/$name.lsy" "$@" >"$tmp/$name.lsy"
    "$lsyc" run "$tmp/$name.lsy" -o "docs/gallery/$name-edited.png" --size 480 --guides
}
# Fig. 4 b–c: the top of the trunk dragged to the right, its lower guides held; the
# leaves, snapped to the trunk's top, follow.
edited palm --by trunk3.v2=30,-5 --by trunk3.v3=30,-5 --pin trunk1 --pin trunk2
# Fig. 1 b–c: two clusters scaled up and the top of the crown raised, the trunk held.
edited tree --pin trunk --scale clusterR2=1.3 --scale clusterL2=1.3 --by top.v4=0,30 --by top.v5=0,30
# Fig. 9b: two cable vertices dragged down, the deck and the towers held; the hangers
# regrow at the same spacing.
edited bridge --by main1.v2=0,-30 --by main8.v3=0,-30 --pin deck --pin towerL --pin towerR

# 3D and growth outputs (README "3D and growth outputs"): the bush from two
# cameras, its growth as frames (--frames) and as one animated PNG (.apng, kept
# under a .png name so that every viewer shows it).
"$lsyc" run lang-examples/bush-3d.lsy -n 5 --size 400 -o docs/gallery/bush-3d-view-30-20.png
"$lsyc" run lang-examples/bush-3d.lsy -n 5 --size 400 --view 75,60 -o docs/gallery/bush-3d-view-75-60.png
"$lsyc" run lang-examples/bush-3d.lsy -n 6 --size 200 --frames -o "$tmp/bush-3d-step.png"
for k in 002 003 004 005 006; do
    cp "$tmp/bush-3d-step-$k.png" "docs/gallery/bush-3d-step-$k.png"
done
"$lsyc" run lang-examples/bush-3d.lsy -n 6 --size 320 -o "$tmp/bush-3d-growth.apng"
cp "$tmp/bush-3d-growth.apng" docs/gallery/bush-3d-growth.png
