"""Mitsuba 3's mi.cornell_box() for the benchmark, and its translation into a pathlab scene.

    python3 bench/mitsuba/mitsuba_scene.py [OUT.json]

writes the pathlab scene (default bench/scenes/mitsuba-cornell-box.json) from the dictionary
that the installed Mitsuba returns, so every transform, colour, the light and the camera are
Mitsuba's own float32 values. The translation, convention by convention (docs/performance.md,
"Against Mitsuba 3"):

- Shapes: Mitsuba's `rectangle` is [-1,1]^2 in z = 0 with normal +z and its `cube` is [-1,1]^3
  with outward normals, exactly pathlab's `rectangle` and `box`; each `to_world` becomes a
  pathlab `matrix` step (row by row, float32 values written so they read back to the same bits).
- Materials: Mitsuba's `diffuse` is one-sided (black from behind, no `twosided` wrapper), so every
  pathlab material has `one_sided: true`. It matters only at the light: the lamp hangs 0.01 below
  the ceiling and paths in that gap meet its back. The lamp is a shape with BOTH an area emitter
  and the white BSDF in Mitsuba, so in pathlab it is a `diffuse` with the white albedo and
  `emission` (not an `emissive`, which reflects nothing). Mitsuba area emitters emit from the
  front side only: pathlab's default (`two_sided: false`). RGB values are used as-is in Mitsuba's
  *_rgb variants, as in pathlab (linear sRGB/Rec. 709).
- Depth: Mitsuba's `max_depth` M counts path segments including the one to the light (1 = only
  emitters seen directly); pathlab's `max_depth` D counts scattering events (0 = emitters seen
  directly), so D = M - 1. Mitsuba starts Russian roulette after the BSDF sample at the vertex
  where its depth counter reaches rr_depth (default 5: vertices 5, 6, ...); pathlab at vertices
  k > rr_depth, so rr_depth 4. (Mitsuba's survival probability is capped at 0.95, pathlab's at
  1: the same expectation, slightly different variance.)
- Camera: Mitsuba's to_world diag(-1, 1, -1) at (0, 0, 3.9) looks down -z with +y up; its fov
  39.3077 is along the smaller axis, which for a square film is pathlab's vertical `fov_y`.
- Film: 512 x 512 (mi.cornell_box() says 256 x 256) and a box filter in both renderers
  (mi.cornell_box() says gaussian, which pathlab does not have; a box filter is the plain mean of
  the samples in the pixel in both).
"""
import json
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
DEFAULT_OUT = os.path.join(REPO, "bench", "scenes", "mitsuba-cornell-box.json")

MITSUBA_MAX_DEPTH = 8      # mi.cornell_box()'s integrator
MITSUBA_RR_DEPTH = 5       # the path integrator's default


def mitsuba_dict(mi, resolution=512, spp=64, max_depth=MITSUBA_MAX_DEPTH):
    """mi.cornell_box() as rendered by the benchmark: square film, box filter, `spp` samples."""
    d = mi.cornell_box()
    film = d["sensor"]["film"]
    film["width"] = resolution
    film["height"] = resolution
    film["rfilter"] = {"type": "box"}
    d["sensor"]["sampler"] = {"type": "independent", "sample_count": spp}
    d["integrator"] = {"type": "path", "max_depth": max_depth, "rr_depth": MITSUBA_RR_DEPTH}
    return d


def _num(x):
    """Shortest text that reads back to the same float32 (pathlab stores floats)."""
    import numpy as np
    s = str(np.float32(x))
    return float(s) if ("." in s or "e" in s) else int(s)


def _matrix(transform):
    import numpy as np
    m = np.array(transform.matrix, dtype=np.float32)
    assert m.shape == (4, 4) and list(m[3]) == [0, 0, 0, 1], m
    return [_num(v) for v in m.flatten()]


def pathlab_scene(mi, d=None):
    """The pathlab scene (a dict) equivalent to mi.cornell_box() as mitsuba_dict() renders it."""
    import numpy as np
    if d is None:
        d = mitsuba_dict(mi)
    sensor = d["sensor"]
    assert sensor["type"] == "perspective" and sensor["film"]["width"] == sensor["film"]["height"]
    cam = np.array(sensor["to_world"].matrix, dtype=np.float64)
    position = cam[:3, 3]
    forward = cam[:3, 2]          # Mitsuba cameras look along local +z
    up = cam[:3, 1]
    assert sensor.get("fov_axis", "x") in ("x", "y", "smaller", "larger")  # square: all the same

    materials = {}
    for name, v in d.items():
        if isinstance(v, dict) and v.get("type") == "diffuse":
            refl = v["reflectance"]
            assert refl["type"] == "rgb", refl
            materials[name] = {"type": "diffuse", "albedo": [_num(c) for c in refl["value"]],
                               "one_sided": True}

    shapes = []
    for name, v in d.items():
        if not (isinstance(v, dict) and v.get("type") in ("rectangle", "cube")):
            continue
        bsdf = v["bsdf"]
        assert bsdf["type"] == "ref", bsdf
        material = bsdf["id"]
        if "emitter" in v:
            em = v["emitter"]
            assert em["type"] == "area" and em["radiance"]["type"] == "rgb", em
            base = materials[material]
            material = name
            materials[name] = {"type": "diffuse", "albedo": base["albedo"],
                               "emission": [_num(c) for c in em["radiance"]["value"]],
                               "two_sided": False, "one_sided": True}
        shapes.append({"type": "rectangle" if v["type"] == "rectangle" else "box",
                       "material": material,
                       "transform": {"matrix": _matrix(v["to_world"])}})

    film = sensor["film"]
    integ = d["integrator"]
    assert integ["type"] == "path"
    return {
        "pathlab_scene": 1,
        "camera": {"position": [_num(c) for c in position],
                   "look_at": [_num(c) for c in position + forward],
                   "up": [_num(c) for c in up],
                   "fov_y": _num(sensor["fov"])},
        "film": {"resolution": [film["width"], film["height"]], "filter": "box"},
        "render": {"spp": sensor["sampler"]["sample_count"],
                   "max_depth": integ["max_depth"] - 1,
                   "rr_depth": integ.get("rr_depth", MITSUBA_RR_DEPTH) - 1,
                   "strategy": "mis", "sampler": "independent", "seed": 0},
        "materials": materials,
        "shapes": shapes,
    }


def dumps(scene):
    """JSON with one shape or material per line, so a diff of the file stays readable."""
    lines = ["{"]
    keys = list(scene)
    for i, k in enumerate(keys):
        v = scene[k]
        end = "," if i + 1 < len(keys) else ""
        if k in ("materials",):
            lines.append(f'  "{k}": {{')
            items = list(v.items())
            for j, (name, m) in enumerate(items):
                lines.append(f"    {json.dumps(name)}: {json.dumps(m)}" + ("," if j + 1 < len(items) else ""))
            lines.append("  }" + end)
        elif k == "shapes":
            lines.append(f'  "{k}": [')
            for j, s in enumerate(v):
                lines.append(f"    {json.dumps(s)}" + ("," if j + 1 < len(v) else ""))
            lines.append("  ]" + end)
        else:
            lines.append(f'  "{k}": {json.dumps(v)}{end}')
    lines.append("}")
    return "\n".join(lines) + "\n"


def main():
    import mitsuba as mi
    mi.set_variant("scalar_rgb")
    out = sys.argv[1] if len(sys.argv) > 1 else DEFAULT_OUT
    text = dumps(pathlab_scene(mi))
    json.loads(text)
    with open(out, "w") as f:
        f.write(text)
    print(f"wrote {out} from mitsuba {mi.__version__}'s mi.cornell_box()")


if __name__ == "__main__":
    main()
