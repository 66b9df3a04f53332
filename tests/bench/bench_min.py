#!/usr/bin/env python3
# The minimum real and CPU time per benchmark over several repetitions (the
# fairest figure on a shared machine). Used for the ## Erosion figures in
# docs/benchmarks.md.
# usage: bench_min.py BENCH FILTER [reps]  -> min real and cpu time per benchmark name
import json, subprocess, sys
b, f = sys.argv[1], sys.argv[2]
reps = sys.argv[3] if len(sys.argv) > 3 else "5"
out = subprocess.run([b, f"--benchmark_filter={f}", f"--benchmark_repetitions={reps}", "--benchmark_min_time=0.1",
                      "--benchmark_format=json"], capture_output=True, text=True).stdout
res = {}
for r in json.loads(out)["benchmarks"]:
    if r.get("run_type") != "iteration": continue
    n = r["run_name"]
    rt, ct = r["real_time"], r["cpu_time"]
    a = res.setdefault(n, [1e30, 1e30, r.get("time_unit")])
    a[0] = min(a[0], rt); a[1] = min(a[1], ct)
for n, (rt, ct, u) in res.items():
    print(f"{n:70s} real {rt:8.3f} {u}  cpu {ct:8.3f} {u}")
