#!/usr/bin/env python3
"""Self-check of the Mitsuba comparison (no pytest; NOT in ctest: it needs Mitsuba).

    python3 bench/mitsuba/selfcheck.py            # seconds: scene file, bias test on synthetic data
    python3 bench/mitsuba/selfcheck.py --render   # + compare.py end to end at 64^2 (about a minute),
                                                  #   and with Mitsuba's max_depth off by one, which
                                                  #   the bias test must call a mismatch

Prints one line per check and 'N passed, N failed'; exits non-zero if any failed.
"""
import json
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, HERE)

results = []


def check(name, ok, detail=""):
    results.append(ok)
    print(f"{'ok  ' if ok else 'FAIL'} {name}" + (f": {detail}" if detail else ""), flush=True)


def scene_file_is_current():
    import mitsuba as mi
    import mitsuba_scene
    mi.set_variant("scalar_rgb")
    with open(mitsuba_scene.DEFAULT_OUT) as f:
        committed = json.load(f)
    fresh = json.loads(mitsuba_scene.dumps(mitsuba_scene.pathlab_scene(mi)))
    check("bench/scenes/mitsuba-cornell-box.json is what mi.cornell_box() of mitsuba "
          f"{mi.__version__} translates to", committed == fresh)


def bias_test_is_calibrated():
    """compare.bias_test on synthetic renders with known noise (5 rounds of 128^2, 30 % noise per
    pixel, 8 x 8 blocks, as compare.py runs it): without bias it must cry wolf in about alpha = 1 %
    of trials (here at most 4 of 100), and a 1 % bias it must find in every trial (expected z ~ 8)."""
    import numpy as np
    import compare
    rng = np.random.default_rng(20)
    h = w = 128
    rounds, trials = 5, 100
    keep = np.ones((h, w), dtype=bool)
    keep[:8, 60:70] = False
    bound = compare.sidak(0.01, 3)
    for bias in (0.0, 0.01):
        alarms, zmax = 0, []
        for _ in range(trials):
            truth = rng.uniform(0.05, 1.0, size=(h, w, 3))
            st = truth * (1 + bias) + 0.3 * truth * rng.standard_normal((rounds, h, w, 3))
            var = st.var(axis=0, ddof=1) / rounds
            z, zb = compare.bias_test(st.mean(axis=0) - truth, var, keep, 8)
            zb_bound = compare.sidak(0.01, len(zb))
            alarms += not (all(abs(x) < bound for x in z) and all(abs(x) < zb_bound for x in zb))
            zmax.append(max(abs(x) for x in z))
        ok = alarms <= 4 if bias == 0 else alarms == trials
        check(f"bias test, {bias:.0%} bias: {alarms} of {trials} trials called a mismatch "
              f"({'at most 4 wanted' if bias == 0 else 'all wanted'})", ok,
              f"median largest channel |z| {float(np.median(zmax)):.1f} (bound {bound:.2f})")


def end_to_end():
    out = tempfile.mkdtemp(prefix="pathlab-mitsuba-selfcheck-")
    base = [sys.executable, os.path.join(HERE, "compare.py"), "--resolution", "64", "--spp", "16",
            "--rounds", "3", "--ref-spp", "512", "--no-warmup", "--out", out]
    p = subprocess.run(base, capture_output=True, text=True)
    check("compare.py at 64^2: every renderer renders the reference's image (exit 0)", p.returncode == 0,
          "" if p.returncode == 0 else p.stdout[-2000:] + p.stderr[-2000:])
    # Mitsuba one bounce deeper than pathlab; the reference by pathlab (a Mitsuba reference would
    # take the same wrong depth). 64 spp: the effect is about +0.8 %, 8 standard errors.
    planted = [sys.executable, os.path.join(HERE, "compare.py"), "--resolution", "64", "--spp", "64",
               "--rounds", "3", "--ref-spp", "1024", "--no-warmup", "--out", out,
               "--ref-renderer", "pathlab-wavefront", "--mitsuba-max-depth", "9",
               "--renderers", "mitsuba-scalar,pathlab-reference"]
    p = subprocess.run(planted, capture_output=True, text=True)
    lines = [ln.strip() for ln in p.stdout.splitlines()
             if ln.startswith("| mitsuba-scalar") or ln.startswith("  mitsuba-scalar: ") and "render_mitsuba" not in ln]
    check("compare.py with Mitsuba's max_depth 9 (pathlab's 7): Mitsuba is a mismatch (exit 1)",
          p.returncode == 1 and any("NO" in ln for ln in lines), " / ".join(lines))


def main():
    scene_file_is_current()
    bias_test_is_calibrated()
    if "--render" in sys.argv[1:]:
        end_to_end()
    failed = results.count(False)
    print(f"{len(results) - failed} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
