#!/usr/bin/env bash
# Builds the seed corpora of the fuzz targets from the repository's own files
# (not committed: fuzz/corpus/ is ignored). The smoke test in `cargo test`
# (tests/it/fuzz_smoke.rs) replays the same files, chosen by the same rule:
#   frontend, lsp: lang-examples/*.lsy and tests/data/**/*.lsy
#   svg_reader:    tests/data/**/*.svg
# each at most 64 KiB (larger seeds slow every execution that mutates them).
# Usage: fuzz/seed.sh   (from anywhere; replaces fuzz/corpus/*/seed-*)
set -euo pipefail
cd "$(dirname "$0")/.."
max=65536
seed() { # target, files...
  local dir="fuzz/corpus/$1"; shift
  mkdir -p "$dir"
  rm -f "$dir"/seed-*
  for f in "$@"; do
    [ "$(stat -c %s "$f")" -le "$max" ] || continue
    cp "$f" "$dir/seed-$(sha1sum "$f" | cut -c1-16)"
  done
  echo "$dir: $(ls "$dir" | wc -l) files, $(du -sh "$dir" | cut -f1)"
}
mapfile -t lsy < <(find lang-examples tests/data -name '*.lsy' | sort)
mapfile -t svg < <(find tests/data -name '*.svg' | sort)
seed frontend "${lsy[@]}"
seed lsp "${lsy[@]}"
seed svg_reader "${svg[@]}"
