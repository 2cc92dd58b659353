#!/usr/bin/env python3
"""Mutation testing for pathlab: does the test suite catch realistic bugs?

Each file in tools/mutate/mutations/ is one small patch (a planted bug, with
a comment header saying what it is). For each, this script applies it to a
scratch worktree of the repository, rebuilds incrementally, runs a test
selection and records whether the tests KILLED the mutant (a test failed,
and which), let it SURVIVE (everything passed) or it did not build
(BUILD-FAILED, not counted in the kill rate). Then it reverts the patch and
goes on. Python's standard library only.

  tools/mutate/run.py                          # every mutation, the whole suite
  tools/mutate/run.py --subset fast            # the fast closed-form tests only
  tools/mutate/run.py --subset fast,unit,full  # a cascade: each mutant meets the cheaper tests first
  tools/mutate/run.py --only 'bsdf-*' --only film-variance-no-bessel
  tools/mutate/run.py --test pathlab_unit_tests:'Film*:Bsdf*' --test pathlab_value_tests
  tools/mutate/run.py --check                  # does every mutation still apply to the tree? (ctest mutations_apply)

The scratch worktree (default $TMPDIR/pathlab-mutate) is a detached
`git worktree` of the repository's HEAD: commit what you want mutated. Its
build directory persists between runs, so only the first build is full.
See docs/mutation-testing.md.
"""

import argparse
import fnmatch
import json
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

# Test selections. "full" is the whole registered suite (every ctest test but
# the hours-long "long" label); "unit" the fast CI label; "fast" the
# closed-form value tests alone (one small binary, seconds to rebuild).
# mutations_apply is left out: in a mutated tree its own patch no longer
# applies, and it would "kill" every mutant.
SUBSETS = {
    "full": {"ctest": ["-LE", "long", "-E", "^mutations_apply$"], "build": ["all"]},
    "unit": {"ctest": ["-L", "unit", "-E", "^mutations_apply$"], "build": ["all"]},
    "fast": {"tests": ["pathlab_value_tests"]},
}


def run(cmd, cwd=None, timeout=None, env=None):
    """Runs cmd; returns (returncode, combined output). A timeout is rc 124."""
    try:
        p = subprocess.run(cmd, cwd=cwd, timeout=timeout, env=env, stdout=subprocess.PIPE,
                           stderr=subprocess.STDOUT, text=True, errors="replace")
        return p.returncode, p.stdout
    except subprocess.TimeoutExpired as e:
        out = e.stdout.decode(errors="replace") if isinstance(e.stdout, bytes) else (e.stdout or "")
        return 124, out + f"\n[mutate] timed out after {timeout} s\n"


def describe(patch):
    """The first '#' comment line of a patch file: what the bug is."""
    for line in patch.read_text().splitlines():
        if line.startswith("#"):
            return line.lstrip("# ").strip()
        if line.startswith("diff ") or line.startswith("---"):
            break
    return ""


def patched_files(patch):
    return [m.group(1) for m in re.finditer(r"^\+\+\+ b/(\S+)", patch.read_text(), re.M)]


class Scratch:
    def __init__(self, repo, path, build_dir, cmake_args, jobs, rev="HEAD"):
        self.repo, self.path, self.build, self.cmake_args, self.jobs = repo, path, build_dir, cmake_args, jobs
        self.rev = rev
        self.log = None

    def prepare(self):
        rc, out = run(["git", "-C", str(self.repo), "rev-parse", "--verify", self.rev + "^{commit}"])
        if rc != 0:
            sys.exit(f"mutate: --rev {self.rev}: not a commit of {self.repo}")
        head = out.strip()
        if not (self.path / ".git").exists():
            rc, out = run(["git", "-C", str(self.repo), "worktree", "add", "--detach", str(self.path), head])
            if rc != 0:
                sys.exit(f"mutate: cannot create the scratch worktree {self.path}:\n{out}")
        else:
            run(["git", "-C", str(self.path), "checkout", "--quiet", "--detach", head])
        self.reset()
        # Inside the (ignored) build folder: an untracked log in the tree would
        # name this machine's paths and fail pathlab_portable.
        self.build.mkdir(parents=True, exist_ok=True)
        self.log = open(self.build / "mutate.log", "w")
        if not (self.build / "build.ninja").exists():
            rc, out = run(["cmake", "-S", str(self.path), "-B", str(self.build), "-G", "Ninja",
                           "-DPATHLAB_WERROR=ON"] + self.cmake_args)
            self.log.write(out)
            if rc != 0:
                sys.exit(f"mutate: cmake failed in {self.build} (see the log)")
        return head

    def reset(self):
        # Restores every tracked file (a patch only edits tracked files).
        run(["git", "-C", str(self.path), "checkout", "--quiet", "--", "."])

    def apply(self, patch):
        rc, out = run(["git", "-C", str(self.path), "apply", "--whitespace=nowarn", str(patch)])
        return rc == 0, out

    def build_targets(self, targets, timeout):
        cmd = ["cmake", "--build", str(self.build), "-j", str(self.jobs)]
        for t in targets:
            cmd += ["--target", t]
        return run(cmd, timeout=timeout)


def failing_cases(output):
    """gtest's '[  FAILED  ] Suite.Case' lines (unique, in order)."""
    seen = []
    for m in re.finditer(r"^\[  FAILED  \] ([\w/.]+)", output, re.M):
        if m.group(1) not in seen:
            seen.append(m.group(1))
    return seen


def run_selection(scratch, selection, timeout, all_tests):
    """Runs the tests; returns (killed_by or None, output)."""
    if "ctest" in selection:
        rc, out = run(["ctest", "--test-dir", str(scratch.build), "-j", str(scratch.jobs), "--output-on-failure",
                       "--timeout", str(timeout)] + selection["ctest"], timeout=timeout * 4)
        if rc == 0:
            return None, out
        failed = re.findall(r"^\s*\d+ - (\S+) \(", out.split("The following tests FAILED:")[-1], re.M)
        cases = failing_cases(out)
        who = ", ".join(failed) or f"ctest rc {rc}"
        if cases:
            who += ": " + " ".join(cases[:3]) + (" ..." if len(cases) > 3 else "")
        return who, out
    killed, outputs = [], []
    for spec in selection["tests"]:
        binary, _, gfilter = spec.partition(":")
        exe = scratch.build / "tests" / binary
        cmd = [str(exe), "--gtest_brief=1"] + ([f"--gtest_filter={gfilter}"] if gfilter else [])
        rc, out = run(cmd, timeout=timeout)
        outputs.append(out)
        if rc != 0:
            cases = failing_cases(out)
            who = binary + (": " + " ".join(cases[:3]) + (" ..." if len(cases) > 3 else "") if cases
                            else f" rc {rc}")
            killed.append(who)
            if not all_tests:
                break
    return ("; ".join(killed) or None), "\n".join(outputs)


def build_targets_of(selection):
    if "build" in selection:
        return selection["build"]
    return sorted({spec.partition(":")[0] for spec in selection["tests"]})


def check_patches(repo, patches):
    rc, _ = run(["git", "-C", str(repo), "rev-parse", "--is-inside-work-tree"])
    if rc != 0:
        print(f"mutate: {repo} is not a git checkout: nothing to check against")
        return 77
    stale = []
    for p in patches:
        rc, out = run(["git", "-C", str(repo), "apply", "--check", "--whitespace=nowarn", str(p)])
        if rc != 0:
            stale.append(p)
            first = out.strip().splitlines()[0] if out.strip() else f"git apply rc {rc}"
            print(f"mutate: {p.name} no longer applies: {first}")
    if stale:
        print(f"mutate: {len(stale)} of {len(patches)} mutation(s) do not apply: move their context to where the "
              "code is now (the bug they plant must stay the same)")
        return 1
    print(f"mutate: all {len(patches)} mutation(s) apply")
    return 0


def main():
    here = Path(__file__).resolve().parent
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repo", type=Path, default=here.parent.parent, help="the repository (default: this one)")
    ap.add_argument("--scratch", type=Path, default=Path(tempfile.gettempdir()) / "pathlab-mutate",
                    help="scratch worktree (created if missing, reused otherwise)")
    ap.add_argument("--mutations", type=Path, default=here / "mutations", help="directory of *.patch files")
    ap.add_argument("--only", action="append", default=[], metavar="GLOB",
                    help="run only the mutations whose name matches (repeatable)")
    ap.add_argument("--subset", default="full",
                    help="test selection: full (default: the whole suite), unit, fast (pathlab_value_tests), or a "
                         "cascade of them, comma-separated (fast,unit,full): a mutant goes on to the next selection "
                         "only if it survived the last, so the verdict is the last selection's at a fraction of its "
                         "cost when each selection contains the one before")
    ap.add_argument("--test", action="append", default=[], metavar="BINARY[:GTEST_FILTER]",
                    help="run these test binaries instead of --subset (repeatable)")
    ap.add_argument("--all-tests", action="store_true",
                    help="with --test: run every binary even after one has killed the mutant")
    ap.add_argument("--timeout", type=int, default=1800, help="seconds per build and per test run")
    ap.add_argument("--jobs", type=int, default=2, help="build and ctest parallelism")
    ap.add_argument("--data-dir", default=os.environ.get("PATHLAB_DATA_DIR", ""),
                    help="-DPATHLAB_DATA_DIR for the scratch build (default: $PATHLAB_DATA_DIR)")
    ap.add_argument("--cmake-arg", action="append", default=[], help="extra cmake configure argument")
    ap.add_argument("--results", type=Path, default=None,
                    help="write the results as JSON here (rewritten after every mutant)")
    ap.add_argument("--resume", action="store_true",
                    help="with --results: keep the verdicts already in that file for the same HEAD and test "
                         "selection, and run only the other mutations")
    ap.add_argument("--rev", default="HEAD",
                    help="the commit to mutate (default HEAD): a fixed one lets --resume go on across your own commits")
    ap.add_argument("--list", action="store_true", help="list the mutations and exit")
    ap.add_argument("--check", action="store_true",
                    help="check that every mutation applies to the repository's working tree (git apply --check) "
                         "and exit: 0 if all do, 1 naming those that do not, 77 if the repository is not a git "
                         "checkout. A patch whose code has moved would otherwise only show at the next run")
    args = ap.parse_args()

    patches = sorted(args.mutations.glob("*.patch"))
    if args.only:
        patches = [p for p in patches if any(fnmatch.fnmatch(p.stem, g) for g in args.only)]
    if not patches:
        sys.exit("mutate: no mutation selected")
    if args.check:
        return check_patches(args.repo.resolve(), patches)
    if args.list:
        for p in patches:
            print(f"{p.stem:40s} {','.join(patched_files(p)):45s} {describe(p)}")
        return 0

    if args.test:
        stages = [("tests", {"tests": args.test})]
    else:
        names = [n.strip() for n in args.subset.split(",") if n.strip()]
        unknown = [n for n in names if n not in SUBSETS]
        if not names or unknown:
            sys.exit(f"mutate: --subset {args.subset!r}: expected one or more of {', '.join(sorted(SUBSETS))}")
        stages = [(n, SUBSETS[n]) for n in names]
    tests_label = args.test or args.subset
    cmake_args = list(args.cmake_arg) + ([f"-DPATHLAB_DATA_DIR={args.data_dir}"] if args.data_dir else [])
    scratch_path = args.scratch.resolve()
    scratch_path.parent.mkdir(parents=True, exist_ok=True)
    scratch = Scratch(args.repo.resolve(), scratch_path, scratch_path / "build-mutate", cmake_args, args.jobs, args.rev)
    head = scratch.prepare()
    log_path = scratch_path / "build-mutate" / "mutate.log"
    done = {}
    if args.resume and args.results and args.results.exists():
        previous = json.loads(args.results.read_text())
        if previous.get("head") == head and previous.get("tests") == tests_label:
            done = {r["mutation"]: r for r in previous["results"]}
        else:
            print(f"mutate: {args.results} is of another HEAD or test selection: starting afresh", flush=True)

    def save(results):
        if args.results:
            # Verdicts of mutations outside this run's selection (--only) stay in the file.
            merged = dict(done)
            merged.update({r["mutation"]: r for r in results})
            results = [merged[k] for k in sorted(merged)]
            counts = {k: sum(r["status"] == v for r in results)
                      for k, v in (("killed", "KILLED"), ("survived", "SURVIVED"), ("build_failed", "BUILD-FAILED"))}
            tmp = args.results.with_name(args.results.name + ".tmp")
            tmp.write_text(json.dumps({"head": head, "tests": tests_label, "results": results, **counts}, indent=1))
            tmp.replace(args.results)

    with scratch.log as log:
        print(f"mutate: {len(patches)} mutation(s) of {head[:12]} in {scratch_path}, tests: "
              f"{tests_label}; log {log_path}", flush=True)

        # The unmutated tree must build and pass, or every mutant looks killed.
        t0 = time.time()
        for name, selection in stages:
            rc, out = scratch.build_targets(build_targets_of(selection), args.timeout)
            log.write(out)
            if rc != 0:
                sys.exit(f"mutate: the unmutated tree does not build (see {log_path})")
            killer, out = run_selection(scratch, selection, args.timeout, True)
            log.write(out)
            if killer:
                sys.exit(f"mutate: the unmutated tree fails its tests ({name}: {killer}); fix that first")
        print(f"mutate: baseline builds and passes ({time.time() - t0:.0f} s)", flush=True)

        results = []
        for patch in patches:
            if patch.stem in done:
                results.append(done[patch.stem])
                print(f"  {patch.stem:40s} {done[patch.stem]['status']:12s} (kept from {args.results})", flush=True)
                continue
            t0 = time.time()
            scratch.reset()
            log.write(f"\n===== {patch.stem} =====\n")
            ok, out = scratch.apply(patch)
            stage = ""
            if not ok:
                first = out.strip().splitlines()[0] if out.strip() else ""
                status, killer = "BUILD-FAILED", "patch does not apply: " + first
            else:
                status, killer = "SURVIVED", None
                for name, selection in stages:
                    stage = name
                    rc, out = scratch.build_targets(build_targets_of(selection), args.timeout)
                    log.write(out)
                    if rc != 0:
                        status, killer = "BUILD-FAILED", "compile error" if rc != 124 else "build timed out"
                        break
                    killer, out = run_selection(scratch, selection, args.timeout, args.all_tests)
                    log.write(out)
                    if killer:
                        status = "KILLED"
                        break
            scratch.reset()
            r = {"mutation": patch.stem, "files": patched_files(patch), "what": describe(patch), "status": status,
                 "killed_by": killer or "", "stage": stage if len(stages) > 1 else "",
                 "seconds": round(time.time() - t0, 1)}
            results.append(r)
            save(results)
            print(f"  {r['mutation']:40s} {status:12s} {(r['stage'] + ': ') if r['stage'] else ''}{r['killed_by']}",
                  flush=True)
        # Leave the scratch tree clean and its build matching it.
        for _, selection in stages:
            scratch.build_targets(build_targets_of(selection), args.timeout)

    killed = sum(r["status"] == "KILLED" for r in results)
    survived = sum(r["status"] == "SURVIVED" for r in results)
    failed = sum(r["status"] == "BUILD-FAILED" for r in results)
    print()
    print(f"{'mutation':40s} {'file':42s} {'status':12s} killed by")
    for r in results:
        by = (r.get("stage") + ": " if r.get("stage") else "") + r["killed_by"]
        print(f"{r['mutation']:40s} {','.join(r['files'])[:42]:42s} {r['status']:12s} {by}")
    rate = 100.0 * killed / (killed + survived) if killed + survived else 0.0
    print(f"\nkilled {killed}, survived {survived}, build-failed {failed}: kill rate {rate:.1f} % "
          f"({killed}/{killed + survived} of the mutants that built)")
    save(results)
    return 0


if __name__ == "__main__":
    sys.exit(main())
