#!/usr/bin/env python3
"""pathlab against Mitsuba 3 on Mitsuba's own Cornell box (issue 20; docs/performance.md,
"Against Mitsuba 3").

One ALTERNATING run: round after round, each renderer renders the scene once, in the same order
(Mitsuba llvm_ad_rgb, Mitsuba scalar_rgb, pathlab --tracer wavefront, pathlab --tracer reference by
default), each as a subprocess timed from start to exit, as a user would run it: process start-up,
(for Mitsuba) Python importing mitsuba, loading the scene, rendering and writing the EXR. Each
round uses its own seed, so the rounds are independent renders. Then per renderer:

- wall seconds (median and range over the rounds), samples/s = pixels x spp / median wall, and the
  in-process render time (Mitsuba: mi.render alone, from render_mitsuba.py; pathlab: the EXR's
  pathlab:render_time_seconds);
- MSE against a shared high-spp reference over every pixel and channel, the pixels that see the
  emitter directly (and their neighbours) left out; the reference's own noise (its per-pixel
  variance of the mean, from independent batches) is subtracted, so the MSE estimates the error
  against the true image; MSE x seconds (median wall); the ratios to Mitsuba llvm_ad_rgb;
- whether it renders the same image as the reference: z-scores of the mean difference (per
  channel, over the whole image, and over a grid of blocks), with the variance estimated from the
  per-pixel spread between independent renders (the rounds, the reference's batches). A bias
  shows as |z| beyond the Sidak-corrected bound.

Needs mitsuba==3.9.1 and numpy (bench/mitsuba/setup.sh) and a built pathlab. Not a test: the
build and the tests do not need Mitsuba.

    python3 bench/mitsuba/compare.py                       # 512^2, 64 spp, 5 rounds
    python3 bench/mitsuba/compare.py --resolution 128 --spp 16 --rounds 4 --ref-spp 1024
    python3 bench/mitsuba/compare.py --pathlab-args "--sampler zsobol"
"""
import argparse
import hashlib
import json
import math
import os
import shlex
import statistics
import subprocess
import sys
import time

try:
    import numpy as np
except ImportError:
    sys.exit(f"compare.py: numpy is not importable by {sys.executable}: run bench/mitsuba/setup.sh")

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, HERE)
import mitsuba_scene  # noqa: E402

LLVM_DEFAULT = "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1"  # Debian 12's libllvm19
RENDERERS = ("mitsuba-llvm", "mitsuba-scalar", "pathlab-wavefront", "pathlab-reference")
BASELINE = "mitsuba-llvm"


def cpu_info():
    info = {}
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if not line.strip():
                    break  # the first processor only
                k, _, v = line.partition(":")
                info[k.strip()] = v.strip()
    except OSError:
        pass
    flags = info.get("flags", "").split()
    return {"vendor": info.get("vendor_id", "?"), "family": info.get("cpu family", "?"),
            "model": info.get("model", "?"), "model_name": info.get("model name", "?"),
            "cores": os.cpu_count(), "avx512f": "avx512f" in flags}


def load1():
    try:
        return os.getloadavg()[0]
    except OSError:
        return float("nan")


class Runner:
    def __init__(self, a):
        self.a = a
        self.env = dict(os.environ)
        self.env.setdefault("DRJIT_LIBLLVM_PATH", LLVM_DEFAULT)
        try:
            import mitsuba as mi
        except ImportError:
            sys.exit(f"compare.py: mitsuba is not importable by {sys.executable}: run bench/mitsuba/setup.sh "
                     "and run compare.py with the Python it installed into")
        mi.set_variant("scalar_rgb")  # in this process only to read EXRs (mi.Bitmap)
        self.mi = mi

    def read(self, path):
        import numpy as np
        b = self.mi.Bitmap(path)
        img = np.array(b, dtype=np.float64)
        meta = {}
        try:
            props = b.metadata()
            for k in props.keys():
                meta[k] = props[k]
        except Exception:  # metadata is only used for pathlab's render time
            pass
        return img[:, :, :3], meta

    def command(self, renderer, spp, seed, out, extra_pathlab=(), scene=None, max_depth=None):
        a = self.a
        if renderer.startswith("mitsuba"):
            variant = "llvm_ad_rgb" if renderer == "mitsuba-llvm" else "scalar_rgb"
            cmd = [a.python, os.path.join(HERE, "render_mitsuba.py"), "--variant", variant,
                   "--resolution", str(a.resolution), "--spp", str(spp), "--seed", str(seed), "-o", out]
            if max_depth is not None:
                cmd += ["--max-depth", str(max_depth)]
            return cmd
        tracer = renderer.split("-", 1)[1]
        cmd = [a.pathlab, "render", scene or a.scene, "--tracer", tracer,
               "--resolution", f"{a.resolution}x{a.resolution}", "--spp", str(spp),
               "--seed", str(seed), "-o", out]
        return cmd + list(extra_pathlab)

    def run(self, renderer, spp, seed, out, **kw):
        cmd = self.command(renderer, spp, seed, out, **kw)
        t0 = time.perf_counter()
        p = subprocess.run(cmd, env=self.env, capture_output=True, text=True)
        wall = time.perf_counter() - t0
        if p.returncode != 0:
            sys.exit(f"compare.py: {renderer} failed (exit {p.returncode}):\n  {shlex.join(cmd)}\n"
                     f"{p.stdout}{p.stderr}")
        img, meta = self.read(out)
        inproc = None
        if renderer.startswith("mitsuba"):
            inproc = json.loads(p.stdout.strip().splitlines()[-1])["render_s"]
        elif "pathlab:render_time_seconds" in meta:
            inproc = float(meta["pathlab:render_time_seconds"])
        return img, wall, inproc, cmd


def sidak(alpha, m):
    """Two-sided z bound for m tests at family-wise level alpha (Sidak)."""
    from statistics import NormalDist
    per = 1.0 - (1.0 - alpha) ** (1.0 / m)
    return NormalDist().inv_cdf(1.0 - per / 2.0)


def bias_test(diff, var, keep, blocks):
    """z-scores of the mean of `diff` (H x W x 3) where `var` is its per-pixel variance."""
    k3 = np.repeat(keep[:, :, None], 3, axis=2)
    z_chan = []
    for c in range(3):
        d = diff[:, :, c][keep]
        v = var[:, :, c][keep]
        z_chan.append(float(d.sum() / math.sqrt(v.sum())))
    h, w = keep.shape
    zb = []
    bh, bw = h // blocks, w // blocks
    for by in range(blocks):
        for bx in range(blocks):
            sl = (slice(by * bh, (by + 1) * bh), slice(bx * bw, (bx + 1) * bw))
            m = k3[sl]
            if m.sum() < 16:
                continue
            for c in range(3):
                mc = m[:, :, c]
                d = diff[sl][:, :, c][mc]
                v = var[sl][:, :, c][mc]
                if v.sum() > 0:
                    zb.append(float(d.sum() / math.sqrt(v.sum())))
                elif abs(d.sum()) > 0:
                    zb.append(float("inf"))
    return z_chan, zb


def rel_diff(diff, var, ref, keep):
    """The mean difference over the kept pixels and channels relative to the reference's mean, and
    its standard error: the smallest bias the run can see is a few of these."""
    k3 = np.repeat(keep[:, :, None], 3, axis=2)
    total = ref[k3].sum()
    return float(diff[k3].sum() / total), float(math.sqrt(var[k3].sum()) / total)


def main():
    ap = argparse.ArgumentParser(description="pathlab against Mitsuba 3 on mi.cornell_box()",
                                 formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__)
    ap.add_argument("--resolution", type=int, default=512, help="square film side (default 512)")
    ap.add_argument("--spp", type=int, default=64, help="samples per pixel of each timed render (64)")
    ap.add_argument("--rounds", type=int, default=5, help="alternating rounds (5; at least 3)")
    ap.add_argument("--renderers", default=",".join(RENDERERS),
                    help="comma-separated, in the order of each round: " + ", ".join(RENDERERS))
    ap.add_argument("--ref-renderer", default="mitsuba-llvm", choices=RENDERERS,
                    help="who renders the shared reference (default mitsuba-llvm: the fastest here, "
                         "and independent of the code under test; pathlab-wavefront works as well)")
    ap.add_argument("--ref-spp", type=int, default=4096, help="reference samples per pixel (4096)")
    ap.add_argument("--ref-batches", type=int, default=8,
                    help="independent batches the reference is rendered in, for its variance (8)")
    ap.add_argument("--pathlab", default=os.path.join(REPO, "build", "pathlab"))
    ap.add_argument("--scene", default=os.path.join(REPO, "bench", "scenes", "mitsuba-cornell-box.json"),
                    help="the pathlab scene (the translation of mi.cornell_box())")
    ap.add_argument("--pathlab-args", default="",
                    help="extra options for the timed pathlab renders, e.g. \"--sampler zsobol\" or "
                         "\"--light-sampling solid_angle\" (not for the reference or the mask)")
    ap.add_argument("--two-sided", action="store_true",
                    help="render pathlab's side with every material two-sided (an approximation: "
                         "the lamp's back then reflects in its 0.01 gap under the ceiling; it lets "
                         "the wavefront run its vectorised stages)")
    ap.add_argument("--mitsuba-max-depth", type=int, default=mitsuba_scene.MITSUBA_MAX_DEPTH,
                    help="Mitsuba's max_depth (8, as mi.cornell_box())")
    ap.add_argument("--python", default=sys.executable, help="the Python that runs Mitsuba")
    ap.add_argument("--out", default=os.path.join(REPO, "out", "mitsuba-bench"),
                    help="images, the cached reference and results.json")
    ap.add_argument("--blocks", type=int, default=8, help="blocks per side for the local bias test")
    ap.add_argument("--alpha", type=float, default=0.01, help="family-wise level of the bias tests")
    ap.add_argument("--no-warmup", action="store_true",
                    help="skip the untimed first render of each renderer (Dr.Jit's kernel cache, the "
                         "file cache)")
    a = ap.parse_args()
    renderers = [r.strip() for r in a.renderers.split(",") if r.strip()]
    for r in renderers:
        if r not in RENDERERS:
            sys.exit(f"compare.py: --renderers: unknown renderer '{r}' (known: {', '.join(RENDERERS)})")
    if a.rounds < 3:
        sys.exit("compare.py: --rounds must be at least 3 (the bias test estimates the variance from them)")
    if a.ref_batches < 2:
        sys.exit("compare.py: --ref-batches must be at least 2")
    if not os.access(a.pathlab, os.X_OK):
        sys.exit(f"compare.py: {a.pathlab}: no pathlab binary (cmake --build build --target pathlab)")
    os.makedirs(a.out, exist_ok=True)
    extra = shlex.split(a.pathlab_args)
    run = Runner(a)

    timed_scene = a.scene  # what the timed pathlab renders read; the reference reads a.scene
    if a.two_sided:
        with open(a.scene) as f:
            sc = json.load(f)
        for m in sc["materials"].values():
            m.pop("one_sided", None)
        timed_scene = os.path.join(a.out, "mitsuba-cornell-box-two-sided.json")
        with open(timed_scene, "w") as f:
            json.dump(sc, f, indent=1)
    with open(a.scene, "rb") as f:
        scene_hash = hashlib.sha256(f.read()).hexdigest()[:12]

    cpu = cpu_info()
    print(f"CPU: {cpu['vendor']} family {cpu['family']} model {cpu['model']} ({cpu['model_name']}), "
          f"{cpu['cores']} logical cores, AVX-512: {'yes' if cpu['avx512f'] else 'no'}")
    print(f"load average (1 min) at the start: {load1():.2f}")
    print(f"scene: {os.path.relpath(timed_scene, REPO)}  {a.resolution}x{a.resolution}, {a.spp} spp, "
          f"{a.rounds} rounds; Mitsuba max_depth {a.mitsuba_max_depth} = pathlab's "
          f"{a.mitsuba_max_depth - 1}; pathlab args: {a.pathlab_args or '(none)'}")

    # --- the pixels that see the emitter: pathlab --max-depth 0 (emission seen directly only),
    # any non-zero pixel, and the 8 pixels around each (partly covered pixels its samples missed).
    mask_img, _, _, _ = run.run("pathlab-reference", 64, 7, os.path.join(a.out, "emitter-mask.exr"),
                                extra_pathlab=["--max-depth", "0"])
    emit = mask_img.max(axis=2) > 0
    padded = np.pad(emit, 1)
    h, w = emit.shape
    grown = np.zeros_like(emit)
    for dy in range(3):
        for dx in range(3):
            grown |= padded[dy:dy + h, dx:dx + w]
    keep = ~grown
    print(f"emitter pixels left out: {int((~keep).sum())} of {keep.size} "
          f"({int(emit.sum())} see it, the rest border them)")

    # --- the shared reference, in independent batches (cached)
    ref_path = os.path.join(a.out, f"ref-{a.ref_renderer}-{a.resolution}-{a.ref_spp}x{a.ref_batches}"
                                   f"-md{a.mitsuba_max_depth}-{scene_hash}.npz")
    if os.path.exists(ref_path):
        z = np.load(ref_path)
        ref, ref_var = z["mean"], z["var_of_mean"]
        print(f"reference: {os.path.relpath(ref_path, REPO)} (cached)")
    else:
        per = max(1, a.ref_spp // a.ref_batches)
        t0 = time.perf_counter()
        imgs = []
        for b in range(a.ref_batches):
            img, _, _, _ = run.run(a.ref_renderer, per, 1_000_000 + b,
                                   os.path.join(a.out, f"ref-batch{b}.exr"),
                                   max_depth=a.mitsuba_max_depth)
            imgs.append(img)
        st = np.stack(imgs)
        ref = st.mean(axis=0)
        ref_var = st.var(axis=0, ddof=1) / len(imgs)
        np.savez_compressed(ref_path, mean=ref, var_of_mean=ref_var)
        print(f"reference: {a.ref_renderer}, {a.ref_batches} batches x {per} spp in "
              f"{time.perf_counter() - t0:.0f} s -> {os.path.relpath(ref_path, REPO)}")
    ref_noise = float(ref_var[keep].mean())

    # --- warm-up, then the alternating rounds
    kw = {r: ({"extra_pathlab": extra, "scene": timed_scene} if r.startswith("pathlab")
              else {"max_depth": a.mitsuba_max_depth})
          for r in renderers}
    if not a.no_warmup:
        for r in renderers:
            run.run(r, a.spp, 999, os.path.join(a.out, f"warmup-{r}.exr"), **kw[r])
    res = {r: {"wall": [], "inproc": [], "mse": [], "imgs": []} for r in renderers}
    cmds = {}
    for k in range(a.rounds):
        for r in renderers:
            img, wall, inproc, cmd = run.run(r, a.spp, 1 + k, os.path.join(a.out, f"{r}-round{k}.exr"), **kw[r])
            cmds[r] = cmd
            d = res[r]
            d["wall"].append(wall)
            d["inproc"].append(inproc)
            d["mse"].append(float(((img - ref) ** 2)[keep].mean()) - ref_noise)
            d["imgs"].append(img)
        print(f"round {k + 1}/{a.rounds}: " + ", ".join(f"{r} {res[r]['wall'][-1]:.2f} s" for r in renderers)
              + f" (load {load1():.1f})", flush=True)
    print(f"load average (1 min) at the end: {load1():.2f}")

    samples = a.resolution * a.resolution * a.spp
    z_bound = sidak(a.alpha, 3)
    rows = {}
    for r in renderers:
        d = res[r]
        st = np.stack(d["imgs"])
        mean = st.mean(axis=0)
        var = st.var(axis=0, ddof=1) / len(d["imgs"]) + ref_var
        z_chan, zb = bias_test(mean - ref, var, keep, a.blocks)
        rd, rd_se = rel_diff(mean - ref, var, ref, keep)
        zb_bound = sidak(a.alpha, max(1, len(zb)))
        wall = statistics.median(d["wall"])
        mse = statistics.mean(d["mse"])
        inproc = [x for x in d["inproc"] if x is not None]
        rows[r] = {
            "wall_median_s": wall, "wall_min_s": min(d["wall"]), "wall_max_s": max(d["wall"]),
            "inproc_median_s": statistics.median(inproc) if inproc else None,
            "samples_per_s": samples / wall, "mse": mse, "mse_x_s": mse * wall,
            "mse_rounds": d["mse"], "wall_rounds": d["wall"],
            "rel_diff": rd, "rel_diff_se": rd_se, "z_channels": z_chan, "z_bound": z_bound, "z_blocks_max": max(abs(x) for x in zb) if zb else 0.0,
            "z_blocks_bound": zb_bound, "blocks": len(zb),
            "same_image": all(abs(x) < z_bound for x in z_chan) and all(abs(x) < zb_bound for x in zb),
            "command": shlex.join(cmds[r]),
        }
    base = rows.get(BASELINE)

    print()
    print(f"{a.resolution}x{a.resolution}, {a.spp} spp, {a.rounds} alternating rounds; wall = the whole process; "
          f"MSE over {int(keep.sum())} pixels x 3 channels against {a.ref_renderer} at {a.ref_spp} spp "
          f"(its own noise {ref_noise:.3g} subtracted)")
    hdr = ("| renderer | wall s (median, range) | in-process render s | samples/s | MSE | MSE x s "
           "| samples/s vs llvm | MSE x s vs llvm | mean diff. (rel.) | z (R, G, B) | max block z |")
    print(hdr)
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for r in renderers:
        x = rows[r]
        sp = f"{x['samples_per_s'] / base['samples_per_s']:.2f}x" if base else "-"
        me = f"{x['mse_x_s'] / base['mse_x_s']:.2f}x" if base else "-"
        ip = f"{x['inproc_median_s']:.2f}" if x["inproc_median_s"] is not None else "-"
        print(f"| {r} | {x['wall_median_s']:.2f} ({x['wall_min_s']:.2f}-{x['wall_max_s']:.2f}) | {ip} "
              f"| {x['samples_per_s'] / 1e6:.2f} M | {x['mse']:.3g} | {x['mse_x_s']:.3g} | {sp} | {me} "
              f"| {x['rel_diff']:+.2%} ± {x['rel_diff_se']:.2%} | {', '.join(f'{z:+.2f}' for z in x['z_channels'])} | {x['z_blocks_max']:.2f} |")
    print()
    print(f"same image as the reference (|z| < {z_bound:.2f} per channel, block |z| < "
          f"{rows[renderers[0]]['z_blocks_bound']:.2f}; Sidak, family-wise alpha {a.alpha}):")
    for r in renderers:
        print(f"  {r}: {'yes' if rows[r]['same_image'] else 'NO -- a mismatch to track down'}")
    print("commands (the last round; round k has --seed k):")
    for r in renderers:
        print(f"  {r}: {rows[r]['command']}")
    out = {"cpu": cpu, "args": vars(a), "keep_pixels": int(keep.sum()), "reference_noise": ref_noise,
           "results": rows}
    with open(os.path.join(a.out, "results.json"), "w") as f:
        json.dump(out, f, indent=1)
    print(f"results: {os.path.relpath(os.path.join(a.out, 'results.json'), REPO)}")
    return 0 if all(rows[r]["same_image"] for r in renderers) else 1


if __name__ == "__main__":
    sys.exit(main())
