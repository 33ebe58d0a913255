#!/bin/bash
# The issue #12 acceptance checks through the built `texel` command, plus the
# CLI contract for bad .hjif input (exit status 2, one line, no output).
# Usage: cli_interchange.sh TEXEL WORKDIR
set -u
texel=$1
work=$2
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
fail() { echo "FAIL: $*" >&2; exit 1; }
run() { "$@" >/dev/null 2>err.txt || { cat err.txt >&2; fail "$*"; }; }

# Acceptance: decode of the re-imported bitstream equals the render of the original document.
run "$texel" render --seed 7 -o a.texel.json
run "$texel" export a.texel.json -o a.hjif
run "$texel" encode a.hjif -o b.texel
run "$texel" decode b.texel --device tpad -o b.bin
run "$texel" render a.texel.json --device tpad -o a.bin
cmp a.bin b.bin || fail "decode of the re-imported bitstream differs from the render of the document"
# The same bitstream as encoding the document itself (the transcoder's 14-byte form).
run "$texel" encode a.texel.json -o c.texel
cmp b.texel c.texel || fail "the .hjif and the document transcode to different bitstreams"
[ "$(stat -c %s b.texel)" -le 16 ] || fail "bitstream is $(stat -c %s b.texel) bytes"
# Spectrum and info read the samples.
run "$texel" spectrum a.hjif --json
# Export options; a bitstream as input; glTF with its .hjif beside it.
run "$texel" export a.texel.json -o v.hjif --modality vibrotactile-texture --tolerance 0.01 --date 2026-01-02
grep -q '"perception_modality":"Vibrotactile Texture"' v.hjif || fail "modality not written"
grep -q '"date":"2026-01-02T00:00:00Z"' v.hjif || fail "date not written"
run "$texel" export b.texel --device tpad -o fromstream.hjif
run "$texel" export a.texel.json -o scene.gltf
[ -s scene.gltf ] && [ -s scene.hjif ] || fail "glTF export did not write scene.gltf and scene.hjif"
run "$texel" export a.texel.json -o scene2.glb
[ -s scene2.glb ] && [ -s scene2.hjif ] || fail "GLB export did not write scene2.glb and scene2.hjif"

# Bad input: exit 2, one line on stderr, nothing written.
bad() {
  local name=$1 text=$2
  printf '%s' "$text" > "$name"
  "$texel" encode "$name" -o "out-$name.texel" >/dev/null 2>err.txt
  local rc=$?
  [ $rc -eq 2 ] || fail "$name: exit status $rc, expected 2"
  [ "$(wc -l < err.txt)" -eq 1 ] || { cat err.txt >&2; fail "$name: not one line"; }
  [ ! -e "out-$name.texel" ] || fail "$name: output written"
}
bad notjson.hjif '{"version": '
bad wrongtype.hjif '{"version":2023,"profile":"Main","level":1,"date":"2024-01-01","description":"","timescale":1000,"avatars":[],"perceptions":[],"syncs":[]}'
bad missing.hjif '{"profile":"Main"}'
bad deep.hjif "$(printf '[%.0s' $(seq 1 500))"
"$texel" export a.texel.json -o bad.hjif --tolerance 0 >/dev/null 2>err.txt
[ $? -eq 2 ] && [ ! -e bad.hjif ] || fail "--tolerance 0 accepted"
grep -q -- "--tolerance" err.txt || fail "the error does not name --tolerance"
"$texel" export a.texel.json -o bad.txt >/dev/null 2>err.txt
[ $? -eq 2 ] || fail "output extension .txt accepted"

# No silent overwrite: the .hjif beside a glTF asset is replaced only with --force.
cp scene2.hjif keep.hjif
"$texel" export a.texel.json -o scene2.glb >/dev/null 2>err.txt
[ $? -eq 2 ] || fail "GLB export replaced an existing scene2.hjif without --force"
[ "$(wc -l < err.txt)" -eq 1 ] && grep -q -- "--force" err.txt || fail "the refusal is not one line naming --force"
cmp -s scene2.hjif keep.hjif || fail "scene2.hjif changed although the export was refused"
run "$texel" export a.texel.json -o scene2.glb --force

# Binary .hmpg: written, read wherever .hjif is (spectrum), and bit-exact through Texel.
run "$texel" export a.texel.json -o a.hmpg --json
run "$texel" spectrum a.hmpg --json
run "$texel" encode a.hmpg --estimate -o fromhmpg.texel
# Malformed .hmpg: exit 2, one line, nothing written.
badbin() {
  local name=$1
  "$texel" spectrum "$name" --json >/dev/null 2>err.txt
  local rc=$?
  [ $rc -eq 2 ] || fail "$name: exit status $rc, expected 2"
  [ "$(wc -l < err.txt)" -eq 1 ] || { cat err.txt >&2; fail "$name: not one line"; }
}
head -c 100 a.hmpg > truncated.hmpg; badbin truncated.hmpg
printf '\377\377\377\377\377\377\377\377\377\377\377\377' > codes.hmpg; badbin codes.hmpg
# A unit declaring 2^32-1 bytes.
printf '\000\000\000\000\017\377\377\377\360' > huge.hmpg; badbin huge.hmpg
: > empty.hmpg; badbin empty.hmpg

# The reference software's files (third-party, through TEXEL_THIRD_PARTY; skipped visibly without it).
if [ -n "${TEXEL_THIRD_PARTY:-}" ] && [ -d "$TEXEL_THIRD_PARTY/mpeg-haptics-rm-outputs" ]; then
  rm_dir="$TEXEL_THIRD_PARTY/mpeg-haptics-rm-outputs"
  for f in texel-fine-seed7-id1.hjif rm-reencoded.hjif rm-binary.hmpg; do run "$texel" spectrum "$rm_dir/$f" --json; done
  run "$texel" spectrum "$rm_dir/rm-from-ahap.hjif" --swipe-speed 100 --json
else
  echo "SKIPPED: the reference software's files (set TEXEL_THIRD_PARTY to the third-party folder)"
fi
echo "interchange CLI checks passed"
