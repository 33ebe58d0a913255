#!/bin/bash
# Khronos' glTF-Validator (npm gltf-validator, from web/node_modules: `npm ci`
# in web/, which `make test` runs once) on every asset `texel export` writes:
# .gltf and .glb, friction and vibrotactile, one region and two. Fails on any
# report message other than the MPEG extensions being unknown.
# Usage: gltf_validator.sh TEXEL WEB_DIR WORKDIR
set -u
here=$(cd "$(dirname "$0")" && pwd)
texel=$1
web=$2
work=$3
fail() { echo "FAIL: $*" >&2; exit 1; }
[ -f "$web/node_modules/gltf-validator/package.json" ] ||
  fail "gltf-validator is not installed: run 'npm ci' in $web (make test does)"
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
"$texel" render --seed 7 -o a.texel.json >/dev/null || fail "render"
cat > halves.texel.json <<'DOC'
{"format": "texel-document", "version": 3, "device": "tpad", "regions": [
  {"name": "left", "start_mm": 0, "length_mm": 50.88,
   "texture": {"kind": "reference", "name": "4sin", "seed": 1}},
  {"name": "right", "start_mm": 50.88,
   "texture": {"kind": "texel", "central_pitch_db": 10, "irregularity_db": -5, "texel_length_mm": 0.25, "seed": 1,
               "coarse": {"kind": "sine", "period_mm": 5, "phase_deg": 0}, "coarse_strength": 0.5, "fine_strength": 1}}]}
DOC
assets=()
for doc in a halves; do
  for ext in gltf glb; do
    # .gltf and .glb of one stem share the .hjif beside them: the second replaces it (--force).
    "$texel" export $doc.texel.json -o $doc-friction.$ext --force >/dev/null || fail "export $doc .$ext"
    assets+=("$doc-friction.$ext")
  done
done
"$texel" export a.texel.json -o a-vibro.glb --modality vibrotactile-texture >/dev/null || fail "export vibrotactile"
assets+=(a-vibro.glb)
node "$here/validate_gltf.mjs" "$web" "${assets[@]}"
