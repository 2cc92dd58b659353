#!/usr/bin/env python3
"""Efficiency of each sampler x light sampling on every analytic scene.

Runs `pathlab converge` on each scene (one tracer, one strategy, the axes
given) and prints one Markdown table: per scene and configuration the RMSE at
the ladder's last rung, the fitted log-log slope of RMSE against spp (-1/2 is
the Monte Carlo rate; steeper is better), samples per second and efficiency
1 / (relMSE x time), and the efficiency relative to the first configuration.
Python's standard library only.

  tools/efficiency-table.py                       # build/pathlab, every analytic scene
  tools/efficiency-table.py --pathlab build/pathlab --tracer reference --spp 16,64,256,1024 \\
      --samplers independent,zsobol --light-samplings area,solid_angle analytic-scenes/penumbra-box.json

Times are wall-clock and go into samples/s and the efficiency: run it on a
quiet machine, and say which processor (the script prints /proc/cpuinfo's).
"""

import argparse
import csv
import math
import subprocess
import sys
import tempfile
from pathlib import Path


def cpu():
    info = {}
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            k, _, v = line.partition(":")
            k = k.strip()
            if k in ("vendor_id", "cpu family", "model", "model name") and k not in info:
                info[k] = v.strip()
    except OSError:
        pass
    return (f"{info.get('vendor_id', '?')} family {info.get('cpu family', '?')} model {info.get('model', '?')} "
            f"({info.get('model name', '?')})")


def slope(xs, ys):
    lx = [math.log(x) for x in xs]
    ly = [math.log(y) for y in ys]
    mx, my = sum(lx) / len(lx), sum(ly) / len(ly)
    sxx = sum((a - mx) ** 2 for a in lx)
    return sum((a - mx) * (b - my) for a, b in zip(lx, ly)) / sxx if sxx > 0 else float("nan")


def main():
    root = Path(__file__).resolve().parent.parent
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scenes", nargs="*", type=Path, help="scene files (default: analytic-scenes/*.json)")
    ap.add_argument("--pathlab", type=Path, default=root / "build" / "pathlab")
    ap.add_argument("--tracer", default="wavefront")
    ap.add_argument("--strategy", default="mis")
    ap.add_argument("--samplers", default="independent,zsobol")
    ap.add_argument("--light-samplings", default="area,solid_angle")
    ap.add_argument("--spp", default="16,64,256,1024", help="the ladder (the slope is fitted over it)")
    ap.add_argument("--seeds", default="4")
    ap.add_argument("--threads", default="0")
    args = ap.parse_args()
    scenes = args.scenes or sorted((root / "analytic-scenes").glob("*.json"))

    print(f"CPU: {cpu()}; pathlab converge --tracers {args.tracer} --strategies {args.strategy} "
          f"--samplers {args.samplers} --light-samplings {args.light_samplings} --spp {args.spp} "
          f"--seeds {args.seeds}\n")
    print("| scene | configuration | RMSE at the last rung | slope | samples/s | efficiency | relative |")
    print("|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for scene in scenes:
            out = Path(tmp) / scene.stem
            cmd = [str(args.pathlab), "converge", str(scene), "--tracers", args.tracer, "--strategies",
                   args.strategy, "--samplers", args.samplers, "--light-samplings", args.light_samplings,
                   "--spp", args.spp, "--seeds", args.seeds, "--threads", args.threads, "--out", str(out)]
            p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
            if p.returncode != 0:
                sys.exit(f"efficiency-table: {' '.join(cmd)} failed:\n{p.stderr}")
            rows = list(csv.DictReader((out / "converge.csv").open()))
            configs = {}
            for r in rows:
                if r["budget_kind"] != "spp":
                    continue
                key = (r["sampler"], r["light_sampling"])
                configs.setdefault(key, []).append(r)
            base = None
            for (sampler, light_sampling), rs in configs.items():
                spp = [float(r["spp"]) for r in rs]
                rmse = [float(r["rmse"]) for r in rs]
                last = rs[-1]
                eff = float(last["efficiency"])
                base = base or eff
                fitted = slope(spp, rmse) if all(v > 0 for v in rmse) else float("nan")
                print(f"| {scene.stem} | {sampler} {light_sampling} | {float(last['rmse']):.3g} | {fitted:.2f} | "
                      f"{float(last['samples_per_second']):.3g} | {eff:.3g} | {eff / base:.2f} |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
