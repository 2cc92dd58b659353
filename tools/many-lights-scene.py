#!/usr/bin/env python3
"""Writes a pathlab scene lit by many small emitters, for the light BVH.

    tools/many-lights-scene.py OUT.json [--grid 72] [--seed 1] [--light-sampler power|bvh]

A floor and a back wall under a layer, 1 to 1.3 above the floor, of GRID x
GRID small rectangles (2 GRID^2 emitting triangles: 10,368 at the default
72) spread over 12 x 12, so that each point of the floor is lit mostly by
the few lights above it; each rectangle of one of eight
emissive materials whose radiance spans 1 to 100 and of a size that varies
by a factor of 4, so the powers differ by up to 1,600x; one rectangle in five
is tilted by up to 60 degrees and one in seven emits on both sides. Four
boxes lower than the lights stand on the floor as occluders. Only the standard library is used;
the same seed writes the same file.
"""

import argparse
import json
import math
import random


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("out")
    ap.add_argument("--grid", type=int, default=72, help="emitters per side (default 72: 10,368 triangles)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--light-sampler", choices=["power", "bvh"], default="power")
    a = ap.parse_args()
    rng = random.Random(a.seed)

    radiances = [1, 2, 4, 8, 15, 30, 60, 100]
    tints = [[1.0, 0.85, 0.6], [0.6, 0.8, 1.0], [1.0, 0.5, 0.4], [0.7, 1.0, 0.6]]
    materials = {
        "floor": {"type": "diffuse", "albedo": [0.6, 0.6, 0.6]},
        "wall": {"type": "diffuse", "albedo": [0.5, 0.45, 0.4]},
        "block": {"type": "diffuse", "albedo": [0.3, 0.5, 0.7]},
    }
    for i, L in enumerate(radiances):
        for t, tint in enumerate(tints):
            for two in (False, True):
                name = f"lamp{i}_{t}{'_2' if two else ''}"
                materials[name] = {"type": "emissive", "radiance": [round(L * c, 4) for c in tint], "two_sided": two}

    half = 6.0  # the floor spans [-half - 1, half + 1] in x and z, the lights [-half, half]
    shapes = [
        {"type": "rectangle", "material": "floor",
         "transform": [{"scale": half + 1}, {"rotate": {"axis": [1, 0, 0], "angle": -90}}]},
        {"type": "rectangle", "material": "wall",
         "transform": [{"scale": [half + 1, 2.5, 1]}, {"translate": [0, 2.5, -half - 1]}]},
    ]
    for x, z, sx, sy, sz in [(-2.0, -1.0, 0.6, 0.4, 0.6), (1.5, 0.8, 1.0, 0.3, 0.4), (0.0, -3.5, 2.5, 0.35, 0.3),
                             (-3.5, 2.5, 0.4, 0.4, 0.4)]:
        shapes.append({"type": "box", "material": "block",
                       "transform": [{"scale": [sx, sy, sz]}, {"translate": [x, sy, z]}]})

    n = a.grid
    spacing = 2 * half / n
    for i in range(n):
        for j in range(n):
            x = -half + (i + 0.5) * spacing
            z = -half + (j + 0.5) * spacing
            size = spacing * rng.uniform(0.1, 0.4)
            steps = [{"scale": [size, size, 1]}, {"rotate": {"axis": [1, 0, 0], "angle": 90}}]  # facing down
            if rng.random() < 0.2:  # tilted
                axis = rng.choice([[1, 0, 0], [0, 0, 1]])
                steps.append({"rotate": {"axis": axis, "angle": round(rng.uniform(-60, 60), 2)}})
            steps.append({"translate": [round(x, 5), round(1.0 + 0.3 * rng.random(), 5), round(z, 5)]})
            L = rng.randrange(len(radiances))
            name = f"lamp{L}_{rng.randrange(len(tints))}{'_2' if rng.random() < 1 / 7 else ''}"
            shapes.append({"type": "rectangle", "material": name, "transform": steps})

    scene = {
        "pathlab_scene": 1,
        "camera": {"position": [0.0, 4.0, 10.0], "look_at": [0.0, 0.0, 0.0], "fov_y": 55},
        "film": {"resolution": [160, 120]},
        "render": {"spp": 16, "max_depth": 4, "strategy": "mis", "seed": 0, "light_sampler": a.light_sampler},
        "materials": materials,
        "shapes": shapes,
    }
    with open(a.out, "w") as f:
        json.dump(scene, f, separators=(",", ":"))
        f.write("\n")
    print(f"{a.out}: {n * n} emitting rectangles ({2 * n * n} triangles), {len(shapes) - n * n} other shapes")


if __name__ == "__main__":
    main()
