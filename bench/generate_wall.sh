#!/usr/bin/env bash
# Whole `shadergen generate` wall time (load, instantiate, search, emit, SPIR-V, checks) on
# the seeded synthetic libraries of bench_search (10 seeds per size, written as rules, rig
# and fragment files by `bench_search --write-library`), with the Dawn face in the same
# run as the baseline. Prints the markdown table of docs/search.md.
#
#   bench/generate_wall.sh [build-dir]
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$here/build}"
cmake --build "$build" --target bench_search shadergen >&2
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-/tmp}"
python3 - "$build" "$here" <<'PY'
import os, statistics, subprocess, sys, tempfile, time, re
build, here = sys.argv[1], sys.argv[2]
sg = f"{build}/generator/cli/shadergen"
def run(args):
    t0 = time.perf_counter()
    out = subprocess.run([sg, "generate", "-q", "--stats"] + args, capture_output=True, text=True)
    ms = (time.perf_counter() - t0) * 1000
    if out.returncode != 0:
        sys.exit(f"generate failed: {out.stderr}")
    m = re.search(r"of ([0-9.]+) ms", out.stdout)
    cost = re.search(r"vs cost (\d+)", out.stdout).group(1)
    return ms, float(m.group(1)), cost
tmp = tempfile.mkdtemp(prefix="sg-wall-")
dawn = ["--rig", f"{here}/examples/dawn/face.rig.yaml", "-f", f"{here}/examples/dawn/face.frag",
        "-r", f"{here}/examples/dawn/rules.yaml", "-o", f"{tmp}/dawn"]
base = [run(dawn) for _ in range(10)]
base_ms = statistics.median(b[0] for b in base)
rows = [f"| Dawn face | {base_ms:.0f} | {max(b[0] for b in base):.0f} | 1.0 | {statistics.median(b[1] for b in base):.3f} |"]
for rules in (100, 300, 1000, 3000):
    res = []
    for seed in range(1, 11):
        d = f"{tmp}/{rules}-{seed}"
        os.makedirs(d)
        subprocess.run([f"{build}/bench/bench_search", "--write-library", d, str(rules), str(seed)], check=True)
        res.append(run(["--rig", f"{d}/lib.rig.yaml", "-f", f"{d}/lib.frag", "-r", f"{here}/rules/standard.yaml",
                        "-r", f"{d}/lib.rules.yaml", "-o", f"{d}/out"]))
    med = statistics.median(r[0] for r in res)
    rows.append(f"| {rules} rules | {med:.0f} | {max(r[0] for r in res):.0f} | {med / base_ms:.1f} | "
                f"{statistics.median(r[1] for r in res):.3f} |")
print("| input | generate median ms | worst ms | vs Dawn | search median ms |")
print("|---|---:|---:|---:|---:|")
print("\n".join(rows))
subprocess.run(["rm", "-rf", tmp])
PY
