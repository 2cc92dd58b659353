#!/usr/bin/env python3
"""Writes the seed corpus of every fuzz target (fuzz/corpus/<target>/seed-*)
and the scene dictionary (fuzz/scene.dict). Small, made here by hand or from
the repository's own scenes; never from the fetched test data. Run from
anywhere: python3 fuzz/make_corpus.py. Files the fuzzers found (crash-*,
regression inputs) live beside the seeds and are not touched."""

import base64
import json
import re
import struct
import zlib
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
CORPUS = HERE / "corpus"


def put(target, name, data):
    folder = CORPUS / target
    folder.mkdir(parents=True, exist_ok=True)
    if isinstance(data, str):
        data = data.encode()
    (folder / ("seed-" + name)).write_bytes(data)


# ------------------------------------------------------------------ scenes
# The repository's scenes, their files renamed to the ones fuzz/scene.cpp
# leaves in its work folder (tri.obj, tri.ply, sky.hdr).
keys = set()


def collect_keys(value):
    if isinstance(value, dict):
        for k, v in value.items():
            keys.add(k)
            collect_keys(v)
    elif isinstance(value, list):
        for v in value:
            collect_keys(v)
    elif isinstance(value, str):
        keys.add(value)


for path in sorted(list((ROOT / "scenes").glob("*.json")) + list((ROOT / "analytic-scenes").glob("*.json"))):
    text = path.read_text()
    text = re.sub(r'"[^"]*\.(hdr|exr|ppm|pgm|png)"', '"sky.hdr"', text)
    text = re.sub(r'"[^"]*\.obj(\.gz)?"', '"tri.obj"', text)
    text = re.sub(r'"[^"]*\.(ply(\.gz)?|gltf|glb)"', '"tri.ply"', text)
    collect_keys(json.loads(text))
    put("scene", path.stem + ".json", text)

put("scene", "meshes-groups.json", json.dumps({
    "pathlab_scene": 1,
    "camera": {"position": [0, 0, 3], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_y": 40},
    "film": {"resolution": [8, 8], "filter": "bilinear"},
    "materials": {"m": {"type": "disney", "base_color": {"texture": "sky.hdr"}, "roughness": 0.5},
                  "g": {"type": "dielectric", "ior": 1.5},
                  "l": {"type": "emissive", "radiance": [1, 1, 1]}},
    "shapes": [{"type": "mesh", "file": "tri.obj", "material": "m", "normals": "smooth"},
               {"type": "mesh", "file": "tri.ply", "material": "g", "transform": {"scale": 2}},
               {"type": "sphere", "center": [0, 1, 0], "radius": 0.5, "material": "l"}],
    "groups": {"pair": [{"type": "mesh", "file": "tri.ply", "material": "m"}]},
    "instances": [{"group": "pair", "transform": {"translate": [1, 0, 0]}}],
    "lights": [{"type": "point", "position": [0, 2, 0], "intensity": [1, 1, 1]},
               {"type": "environment", "file": "sky.hdr"}],
}, indent=1))
collect_keys(json.loads((CORPUS / "scene" / "seed-meshes-groups.json").read_text()))
for word in ["spot", "directional", "angular_diameter", "uniform", "one_sided", "energy_compensation",
             "normal_map", "alpha", "bsdf_sampling", "cospow", "vndf", "clamp", "min_pdf", "thin_lens",
             "aperture", "focus_distance", "radiance", "gltf", "box", "rectangle", "true", "false", "null"]:
    keys.add(word)
with open(HERE / "scene.dict", "w") as d:
    d.write("# libFuzzer dictionary for fuzz_scene: keys and words of the seed scenes (fuzz/make_corpus.py)\n")
    for k in sorted(keys):
        if 0 < len(k) <= 40 and re.fullmatch(r"[A-Za-z0-9_.+$/ -]+", k):
            d.write('"\\"%s\\""\n' % k)

# -------------------------------------------------------------------- PLY
ply_head = "ply\nformat %s 1.0\n"
put("ply", "ascii-triangle.ply", ply_head % "ascii" +
    "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
    "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")
put("ply", "ascii-quad-normals-uv.ply", ply_head % "ascii" +
    "comment a quad with normals, uv and a colour pathlab ignores\n"
    "element vertex 4\nproperty double x\nproperty double y\nproperty double z\n"
    "property float nx\nproperty float ny\nproperty float nz\nproperty float u\nproperty float v\n"
    "property uchar red\nelement face 1\nproperty list uint8 int32 vertex_index\nend_header\n"
    "0 0 0 0 0 1 0 0 255\n1 0 0 0 0 1 1 0 0\n1 1 0 0 0 1 1 1 0\n0 1 0 0 0 1 0 1 7\n4 0 1 2 3\n")


def binary_ply(endian, fmt):
    head = (ply_head % fmt + "element vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
            "property float s\nproperty float t\n"
            "element face 2\nproperty list uchar uint vertex_indices\nelement edge 0\nproperty int vertex1\n"
            "end_header\n").encode()
    body = b""
    for v in [(0, 0, 0, 0, 0), (1, 0, 0, 1, 0), (1, 1, 0, 1, 1), (0, 1, 0, 0, 1)]:
        body += struct.pack(endian + "5f", *v)
    body += struct.pack(endian + "B3I", 3, 0, 1, 2) + struct.pack(endian + "B3I", 3, 0, 2, 3)
    return head + body


put("ply", "binary-le.ply", binary_ply("<", "binary_little_endian"))
put("ply", "binary-be.ply", binary_ply(">", "binary_big_endian"))

# -------------------------------------------------------------------- OBJ
put("obj", "triangle.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
put("obj", "quad-vt-vn.obj", "# a quad\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
    "vn 0 0 1\nf 1/1/1 2/2/1 3/3/1 4/4/1\n")
put("obj", "groups-materials.obj", "mtllib none.mtl\no thing\ng a\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
    "v 0 0 1\nusemtl red\ns 1\nf 1 2 3\nf 1 3 4\nusemtl blue\ns off\nf -5 -4 -1\ns 2\nf 2//  3// 5//\n")
put("obj", "polygon-negative.obj", "v 0 0 0\nv 2 0 0\nv 2 2 0\nv 1 3 0\nv 0 2 0\nvt 0.5 0.5\nf -5/-1 -4/-1 -3/-1 -2/-1 -1/-1\nl 1 2\np 3\n")

# ------------------------------------------------------------------- glTF
# One triangle: positions, normals, uvs, u16 indices.
pos = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0)
nrm = struct.pack("<9f", 0, 0, 1, 0, 0, 1, 0, 0, 1)
uv = struct.pack("<6f", 0, 0, 1, 0, 0, 1)
idx = struct.pack("<3H", 0, 1, 2) + b"\0\0"
buf = pos + nrm + uv + idx


def png_bytes(width, height, colour_type, rows):
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xffffffff)
    raw = b"".join(b"\0" + r for r in rows)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, colour_type, 0, 0, 0)) +
            chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


png = png_bytes(2, 1, 2, [bytes([255, 0, 0, 0, 255, 0])])


def gltf_doc(uri, image_uri=None):
    doc = {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0, 2, 3]}],
        "nodes": [{"mesh": 0, "children": [1], "translation": [1, 0, 0]},
                  {"mesh": 0, "scale": [2, 2, 2], "rotation": [0, 0, 0, 1]},
                  {"camera": 0, "matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 3, 1]},
                  {"extensions": {"KHR_lights_punctual": {"light": 0}}}],
        "meshes": [{"name": "tri", "primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2},
                                                   "indices": 3, "material": 0}]}],
        "materials": [{"name": "m", "doubleSided": True, "alphaMode": "MASK", "alphaCutoff": 0.5,
                       "pbrMetallicRoughness": {"baseColorFactor": [1, 0.5, 0.5, 1], "metallicFactor": 0.1,
                                                "roughnessFactor": 0.7},
                       "emissiveFactor": [0, 0, 0]}],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.01, "aspectRatio": 1.5}}],
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point", "color": [1, 1, 1], "intensity": 2}]}},
        "buffers": [{"byteLength": len(buf)}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36},
                        {"buffer": 0, "byteOffset": 36, "byteLength": 36},
                        {"buffer": 0, "byteOffset": 72, "byteLength": 24},
                        {"buffer": 0, "byteOffset": 96, "byteLength": 6}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                       "min": [0, 0, 0], "max": [1, 1, 0]},
                      {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC3"},
                      {"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC2"},
                      {"bufferView": 3, "componentType": 5123, "count": 3, "type": "SCALAR"}],
    }
    if uri is not None:
        doc["buffers"][0]["uri"] = uri
    if image_uri is not None:
        doc["images"] = [{"uri": image_uri}]
        doc["samplers"] = [{"magFilter": 9728}]
        doc["textures"] = [{"source": 0, "sampler": 0}]
        doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {"index": 0}
    return doc


data_uri = "data:application/octet-stream;base64," + base64.b64encode(buf).decode()
png_uri = "data:image/png;base64," + base64.b64encode(png).decode()
put("gltf", "triangle.gltf", json.dumps(gltf_doc(data_uri), indent=1))
put("gltf", "textured.gltf", json.dumps(gltf_doc(data_uri, png_uri)))
put("gltf", "external-buffer.gltf", json.dumps(gltf_doc("missing.bin")))


def glb(doc, binary):
    js = json.dumps(doc).encode()
    js += b" " * (-len(js) % 4)
    binary += b"\0" * (-len(binary) % 4)
    body = struct.pack("<I4s", len(js), b"JSON") + js + struct.pack("<I4s", len(binary), b"BIN\0") + binary
    return struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body


put("gltf", "triangle.glb", glb(gltf_doc(None), buf))

# ----------------------------------------------------- partial films (no checksum)


def pfilm(width, height, filt, moments, bad=()):
    n = width * height
    words = [n * 7, n * 6 if moments == "mean_and_variance" else 0, n * 10 if filt == "bilinear" else 0]
    header = {
        "format": "pathlab partial film", "format_version": 1, "pathlab_version": "0.1.0",
        "width": width, "height": height, "filter": filt, "moments": moments,
        "passes": [0, 2], "target_spp": 4, "processes": 1, "resumes": 0,
        "fingerprint": {"digest": "0" * 32, "lines": ["pathlab 0.1.0 unknown", "setting seed 0"]},
        "stats": {"seconds": "0x1p-4", "samples": 2 * n, "rays": 5 * n, "clamped_samples": 0,
                  "energy_total": ["0000000000000010", "0000000000000000"],
                  "energy_clamped": ["0000000000000000", "0000000000000000"]},
        "film_rays": 5 * n, "bad_sample_count": len(bad),
        "bad_samples": [{"x": x, "y": y, "sample": s, "L": ["nan", "inf", "0x1p+0"]} for x, y, s in bad],
        "words": words,
    }
    text = json.dumps(header, indent=1).encode()
    body = b"PLPFILM1" + struct.pack("<Q", len(text)) + text
    for i in range(sum(words)):
        body += struct.pack("<Q", (i * 0x9E3779B97F4A7C15) & 0xFFFF if i % 7 != 6 else 2)
    return body


put("partial_film", "box-mean-2x2.pfilm", pfilm(2, 2, "box", "mean"))
put("partial_film", "bilinear-variance-2x1.pfilm", pfilm(2, 1, "bilinear", "mean_and_variance", [(1, 0, 1)]))
put("partial_film", "box-variance-1x1.pfilm", pfilm(1, 1, "box", "mean_and_variance"))

# -------------------------------------------------------------- env images
for name in ["constant-8x4.hdr", "structured-16x8.hdr"]:
    put("envmap", name, (ROOT / "analytic-scenes" / name).read_bytes())


def rgbe(r, g, b):
    import math
    m = max(r, g, b)
    if m < 1e-32:
        return bytes(4)
    f, e = math.frexp(m)
    s = f * 256.0 / m
    return bytes([int(r * s), int(g * s), int(b * s), e + 128])


flat = b"".join(rgbe(0.5 * x, 1.0, 2.0 * y) for y in range(2) for x in range(4))
put("envmap", "flat-4x2.hdr", b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\nEXPOSURE=1.0\n\n-Y 2 +X 4\n" + flat)
put("envmap", "rgb-4x2.png", png_bytes(4, 2, 2, [bytes(range(12)), bytes(range(100, 112))]))
put("envmap", "grey-2x1.png", png_bytes(2, 1, 0, [bytes([0, 200])]))
put("envmap", "rgba-2x1.png", png_bytes(2, 1, 6, [bytes([1, 2, 3, 4, 5, 6, 7, 8])]))
print("wrote", sum(1 for _ in CORPUS.rglob("seed-*")), "seeds under", CORPUS)
