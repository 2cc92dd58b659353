"""Render mi.cornell_box() (as bench/mitsuba/mitsuba_scene.py sets it up) with Mitsuba 3 and
write an EXR: what a user of Mitsuba would run. compare.py runs this as a subprocess and times the
whole process (Python start-up, importing mitsuba, loading the scene, rendering, writing); the
last line printed is JSON with the in-process times of each step.

    DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1 \
    python3 bench/mitsuba/render_mitsuba.py --variant llvm_ad_rgb --spp 64 --seed 1 -o out.exr
"""
import argparse
import json
import os
import sys
import time

t_start = time.perf_counter()
import mitsuba as mi  # noqa: E402
import drjit as dr    # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import mitsuba_scene  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--resolution", type=int, default=512)
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--max-depth", type=int, default=mitsuba_scene.MITSUBA_MAX_DEPTH,
                    help="Mitsuba's max_depth (1 = emitters seen directly only)")
    ap.add_argument("-o", "--output", required=True)
    a = ap.parse_args()

    mi.set_variant(a.variant)
    t_import = time.perf_counter()
    scene = mi.load_dict(mitsuba_scene.mitsuba_dict(mi, a.resolution, a.spp, a.max_depth))
    t_load = time.perf_counter()
    img = mi.render(scene, spp=a.spp, seed=a.seed)
    dr.eval(img)
    dr.sync_thread()
    t_render = time.perf_counter()
    mi.Bitmap(img).write(a.output)
    t_write = time.perf_counter()
    print(json.dumps({"import_s": t_import - t_start, "load_s": t_load - t_import,
                      "render_s": t_render - t_load, "write_s": t_write - t_render,
                      "variant": a.variant, "mitsuba": mi.__version__}))


if __name__ == "__main__":
    main()
