#!/usr/bin/env bash
# Fetches, verifies (sha256) and converts the real datasets listed in docs/datasets.md into a form
# visopt's readVolume takes. Only Debian's package archive is needed: packages are fetched with
# `apt-get download` (never installed) and single files pulled out with dpkg-deb | tar.
#
# usage: datasets-scripts/fetch_datasets.sh [DEST]     (DEST defaults to <repo>/data)
#
# Result (all volumes load with readVolume):
#   DEST/Cranium.raw + .raw.json          CT head, int16 256x256x108, 0.957x0.957x1.5 mm
#   DEST/skull_2.9.inr                    INRIMAGE-4 float32 64^3 (native reader)
#   DEST/skull_2.9.raw + .raw.json        the same bytes as raw + sidecar (headerBytes 256)
#   DEST/brainsmall.raw + .raw.json       MRI head, uint8 128x128x84 (headerBytes 62)
#   DEST/nAChR_M2_water.plt               gOpenMol plt float32 46x46x78 (native reader)
#   DEST/water.raw + .raw.json            the same bytes as raw + sidecar (headerBytes 44)
#   DEST/meshes/{bunny00,armadillo,head}.off
#   DEST/colin27.nii.gz                   MRI head with scalp (Colin27, MRIcron's ch2), NIfTI
#                                         uint8 181x217x181, 1 mm (native reader, RAS world)
#   DEST/colin27-brain.raw + .raw.json    its brain (ch2bet > 0) as a 0/1 importance volume
# Idempotent: files already present with the right checksum are kept; the downloaded .deb
# files are cached in DEST/.cache/debs. Prints one line per dataset. Exit status: 0 when every
# dataset it could get is fine (missing ones are reported, not fatal), 2 on a checksum mismatch.
set -u

SCRIPT_DIR=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
REPO=$(cd "$SCRIPT_DIR/.." && pwd)
DEST=${1:-$REPO/data}
CACHE=$DEST/.cache/debs
WORK=$(mktemp -d "${TMPDIR:-/tmp}/visopt-fetch.XXXXXX")
trap 'rm -rf "$WORK"' EXIT
mkdir -p "$DEST" "$DEST/meshes" "$CACHE" || { echo "cannot create $DEST" >&2; exit 1; }

mismatch=0
updated=0

say() { printf '%-22s %s\n' "$1" "$2"; }

sha_ok() {  # FILE SHA256
  [ -f "$1" ] && [ "$(sha256sum "$1" | cut -d' ' -f1)" = "$2" ]
}

cached_deb() {  # PKG -> path of a cached .deb of PKG, if any
  local f
  for f in "$CACHE/${1}_"*.deb; do
    if [ -e "$f" ]; then echo "$f"; return 0; fi
  done
  return 1
}

download_deb() {  # PKG VERSION: the pinned version first, else whatever the archive has
  (cd "$CACHE" && { apt-get download "$1=$2" || apt-get download "$1"; }) >>"$WORK/apt-$1.log" 2>&1
}

# deb PKG VERSION -> prints the path of the cached .deb, downloading it when needed; runs
# `apt-get update` once, only when a download fails (e.g. a fresh machine with no lists).
deb() {
  cached_deb "$1" && return 0
  download_deb "$1" "$2"
  cached_deb "$1" && return 0
  if [ "$updated" = 0 ]; then
    updated=1
    apt-get update >"$WORK/apt-update.log" 2>&1 || true
  fi
  download_deb "$1" "$2"
  cached_deb "$1"
}

# member DEB PATH OUT: extracts one file of a .deb.
member() {
  if dpkg-deb --fsys-tarfile "$1" | tar -xO "./$2" >"$3.part" 2>/dev/null && [ -s "$3.part" ]; then
    mv "$3.part" "$3"
  else
    rm -f "$3.part"
    return 1
  fi
}

# install_verified NAME SRC DEST SHA: moves SRC to DEST when its checksum matches.
install_verified() {
  local name=$1 src=$2 out=$3 sha=$4
  if ! sha_ok "$src" "$sha"; then
    say "$name" "failed: checksum mismatch ($(sha256sum "$src" | cut -d' ' -f1), expected $sha)"
    mismatch=1
    return 1
  fi
  cp "$src" "$out.part" && mv "$out.part" "$out"
}

write_file() {  # OUT, content on stdin: atomic
  cat >"$1.part" && mv "$1.part" "$1"
}

# ---------------------------------------------------------------- Cranium (invesalius-examples)
CRANIUM_SHA=d87fd5e6aaf2c4fdf4f3fe28ee3335192fc2464ed8e9682fc78530cb837938da
cranium() {
  if sha_ok "$DEST/Cranium.raw" $CRANIUM_SHA && [ -s "$DEST/Cranium.raw.json" ]; then
    say Cranium "ok (already present)"; return; fi
  local d
  d=$(deb invesalius-examples 3.1.99998-4) || { say Cranium "failed: cannot download invesalius-examples"; return; }
  member "$d" usr/share/doc/invesalius-examples/examples/Cranium.inv3 "$WORK/Cranium.inv3" \
    || { say Cranium "failed: Cranium.inv3 not found in $(basename "$d")"; return; }
  mkdir -p "$WORK/inv3"
  tar -xzf "$WORK/Cranium.inv3" -C "$WORK/inv3" \
    || { say Cranium "failed: cannot unpack Cranium.inv3"; return; }
  local matrix plist
  matrix=$(find "$WORK/inv3" -name matrix.dat | head -n1)
  plist=$(find "$WORK/inv3" -name main.plist | head -n1)
  if [ -z "$matrix" ] || [ -z "$plist" ]; then
    say Cranium "failed: matrix.dat/main.plist missing"; return
  fi
  python3 "$SCRIPT_DIR/dataset_tools.py" cranium-sidecar "$plist" >"$WORK/Cranium.raw.json" \
    || { say Cranium "failed: cannot read main.plist"; return; }
  install_verified Cranium "$matrix" "$DEST/Cranium.raw" $CRANIUM_SHA || return
  write_file "$DEST/Cranium.raw.json" <"$WORK/Cranium.raw.json"
  say Cranium "ok"
}

# ---------------------------------------------------------------- CGAL data: skull + meshes
SKULL_SHA=7a9147c819e426fbd7bf4f0ed5ddac799e54376f64260ef4f650f29e3aa5d4c4
BUNNY_SHA=ab651cb04955c161efaeb079035a1e5e1f0e0d1f816a2df67beaea68f393ff2b
cgal_data() {  # unpacks CGAL's data.tar.gz into $WORK/cgal once
  [ -d "$WORK/cgal/data" ] && return 0
  local d
  d=$(deb libcgal-demo 5.5.1-2) || return 1
  member "$d" usr/share/doc/libcgal-dev/data.tar.gz "$WORK/cgal-data.tar.gz" || return 1
  mkdir -p "$WORK/cgal" && tar -xzf "$WORK/cgal-data.tar.gz" -C "$WORK/cgal" \
    data/images/skull_2.9.inr data/meshes/bunny00.off data/meshes/armadillo.off \
    data/meshes/head.off 2>/dev/null
  [ -d "$WORK/cgal/data" ]
}

skull() {
  if sha_ok "$DEST/skull_2.9.inr" $SKULL_SHA && sha_ok "$DEST/skull_2.9.raw" $SKULL_SHA \
     && [ -s "$DEST/skull_2.9.raw.json" ]; then say skull_2.9 "ok (already present)"; return; fi
  cgal_data || { say skull_2.9 "failed: cannot get libcgal-demo's data.tar.gz"; return; }
  local src=$WORK/cgal/data/images/skull_2.9.inr
  [ -f "$src" ] || { say skull_2.9 "failed: skull_2.9.inr not in data.tar.gz"; return; }
  install_verified skull_2.9 "$src" "$DEST/skull_2.9.inr" $SKULL_SHA || return
  install_verified skull_2.9 "$src" "$DEST/skull_2.9.raw" $SKULL_SHA || return
  write_file "$DEST/skull_2.9.raw.json" <<'JSON'
{"dims": [64, 64, 64], "type": "float32", "spacing": [3.94305, 3.94305, 3.65079],
 "origin": [0, 0, 0], "endian": "little", "headerBytes": 256}
JSON
  say skull_2.9 "ok"
}

meshes() {
  local have=1 m
  for m in bunny00 armadillo head; do [ -s "$DEST/meshes/$m.off" ] || have=0; done
  if [ $have = 1 ] && sha_ok "$DEST/meshes/bunny00.off" $BUNNY_SHA; then
    say meshes "ok (already present)"; return; fi
  cgal_data || { say meshes "failed: cannot get libcgal-demo's data.tar.gz"; return; }
  install_verified meshes "$WORK/cgal/data/meshes/bunny00.off" "$DEST/meshes/bunny00.off" \
    $BUNNY_SHA || return
  for m in armadillo head; do  # no published checksum for these two
    [ -s "$WORK/cgal/data/meshes/$m.off" ] || { say meshes "failed: $m.off missing"; return; }
    cp "$WORK/cgal/data/meshes/$m.off" "$DEST/meshes/$m.off.part" \
      && mv "$DEST/meshes/$m.off.part" "$DEST/meshes/$m.off"
  done
  say meshes "ok (bunny00 verified; armadillo, head unverified)"
}

# ---------------------------------------------------------------- brainsmall (libvolpack1-dev)
BRAIN_SHA=eebfa050a1775f556718c2c9716cb624bc2270392e82176b1ce4812b36d4f286
brainsmall() {
  if sha_ok "$DEST/brainsmall.raw" $BRAIN_SHA && [ -s "$DEST/brainsmall.raw.json" ]; then
    say brainsmall "ok (already present)"; return; fi
  local d
  d=$(deb libvolpack1-dev 1.0b3-9) || { say brainsmall "failed: cannot download libvolpack1-dev"; return; }
  member "$d" usr/share/doc/libvolpack1-dev/examples/brainsmall.den "$WORK/brainsmall.den" \
    || { say brainsmall "failed: brainsmall.den not found"; return; }
  install_verified brainsmall "$WORK/brainsmall.den" "$DEST/brainsmall.raw" $BRAIN_SHA || return
  # 62-byte header of little-endian shorts (map lengths 128 128 84 at shorts 27..29), then
  # uint8 voxels x fastest. The file gives no spacing: unit spacing.
  write_file "$DEST/brainsmall.raw.json" <<'JSON'
{"dims": [128, 128, 84], "type": "uint8", "spacing": [1, 1, 1], "origin": [0, 0, 0],
 "endian": "little", "headerBytes": 62}
JSON
  say brainsmall "ok"
}

# ---------------------------------------------------------------- water (python3-griddataformats)
WATER_SHA=4463236ac7afed50104ea3d2864cf04f4b12eaf0ba81d87df63d6c6ae6a9a829
water() {
  if sha_ok "$DEST/nAChR_M2_water.plt" $WATER_SHA && sha_ok "$DEST/water.raw" $WATER_SHA \
     && [ -s "$DEST/water.raw.json" ]; then say water "ok (already present)"; return; fi
  local d
  d=$(deb python3-griddataformats 1.0.1-1) \
    || { say water "failed: cannot download python3-griddataformats"; return; }
  member "$d" usr/lib/python3/dist-packages/gridData/tests/datafiles/nAChR_M2_water.plt \
    "$WORK/water.plt" || { say water "failed: nAChR_M2_water.plt not found"; return; }
  python3 "$SCRIPT_DIR/dataset_tools.py" plt-sidecar "$WORK/water.plt" >"$WORK/water.raw.json" \
    || { say water "failed: cannot parse the plt header"; return; }
  install_verified water "$WORK/water.plt" "$DEST/nAChR_M2_water.plt" $WATER_SHA || return
  install_verified water "$WORK/water.plt" "$DEST/water.raw" $WATER_SHA || return
  write_file "$DEST/water.raw.json" <"$WORK/water.raw.json"
  say water "ok"
}

# ---------------------------------------------------------------- Colin27 (mricron-data)
# The hold-out scan of docs/real-scans.md: run with the brainsmall MRI's command, never tuned on.
CH2_SHA=a009051127f64dc3dd554d5f5b589870ea72106d9642c21b4e7093e478cfc309
CH2BET_SHA=592a2d20abdf36eefcb540ca8958428040edffc1bc1a18ba1dcfbabac77c5dd1
colin() {
  if sha_ok "$DEST/colin27.nii.gz" $CH2_SHA && [ -s "$DEST/colin27-brain.raw" ] \
     && [ -s "$DEST/colin27-brain.raw.json" ]; then
    say colin27 "ok (already present)"; return; fi
  local d t=usr/share/mricron/templates
  d=$(deb mricron-data 1.2.20211006+dfsg-4) || { say colin27 "failed: cannot download mricron-data"; return; }
  member "$d" $t/ch2.nii.gz "$WORK/ch2.nii.gz" && member "$d" $t/ch2bet.nii.gz "$WORK/ch2bet.nii.gz" \
    || { say colin27 "failed: ch2.nii.gz or ch2bet.nii.gz not found"; return; }
  sha_ok "$WORK/ch2bet.nii.gz" $CH2BET_SHA \
    || { say colin27 "failed: checksum mismatch of ch2bet.nii.gz"; mismatch=1; return; }
  python3 "$SCRIPT_DIR/dataset_tools.py" nifti-mask "$WORK/ch2bet.nii.gz" "$WORK/colin27-brain.raw" \
    || { say colin27 "failed: cannot convert ch2bet.nii.gz"; return; }
  install_verified colin27 "$WORK/ch2.nii.gz" "$DEST/colin27.nii.gz" $CH2_SHA || return
  mv "$WORK/colin27-brain.raw.json" "$DEST/" && mv "$WORK/colin27-brain.raw" "$DEST/" || return
  say colin27 "ok"
}

for tool in apt-get dpkg-deb tar sha256sum python3; do
  command -v $tool >/dev/null || { echo "fetch_datasets.sh: needs $tool" >&2; exit 1; }
done

# The brainsmall head stood upright (a direction matrix on the same voxels: index x runs face to
# back, y top to bottom, z side to side) and its brain mask, the importance of docs/real-scans.md.
brain_extras() {
  [ -f "$DEST/brainsmall.raw" ] || return
  ln -sf brainsmall.raw "$DEST/brainsmall-upright.raw"
  python3 - "$DEST/brainsmall.raw.json" "$DEST/brainsmall-upright.raw.json" <<'PY' || return
import json, sys
m = json.load(open(sys.argv[1]))
m["direction"] = [0, 0, 1, -1, 0, 0, 0, -1, 0]
json.dump(m, open(sys.argv[2], "w"))
PY
  if [ ! -s "$DEST/brainsmall-brain.raw" ]; then
    python3 "$SCRIPT_DIR/brain_mask.py" "$DEST/brainsmall.raw" "$DEST/brainsmall.raw.json" \
      "$DEST/brainsmall-brain.raw" >/dev/null || { say brain-mask "failed"; return; }
  fi
  ln -sf brainsmall-brain.raw "$DEST/brainsmall-brain-upright.raw"
  python3 - "$DEST/brainsmall-brain.raw.json" "$DEST/brainsmall-brain-upright.raw.json" <<'PY' || return
import json, sys
m = json.load(open(sys.argv[1]))
m["direction"] = [0, 0, 1, -1, 0, 0, 0, -1, 0]
json.dump(m, open(sys.argv[2], "w"))
PY
  say brain-mask "ok"
}

cranium
skull
meshes
brainsmall
brain_extras
water
colin

[ $mismatch = 0 ] || exit 2
exit 0
