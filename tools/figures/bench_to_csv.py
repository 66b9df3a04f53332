#!/usr/bin/env python3
"""Google Benchmark JSON from bench_rmp → method,regions,seconds lines for rmp_figures plot.

    build-rmp/bench/bench_rmp --benchmark_format=json > rmp.json
    python3 tools/figures/bench_to_csv.py rmp.json > rmp.csv

Regions per iteration: the cone count, or for the graph method the most
polygons its cuts can make, n(n+1)/2 + 1, as the thesis's table 4.1 lists.
"""
import json
import sys

UNIT = {"ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0}
METHOD = {"BM_RmpVoronoi": "voronoi", "BM_RmpCones": "cones", "BM_RmpGraph": "graph"}

data = json.load(open(sys.argv[1]))
for b in data["benchmarks"]:
    if b.get("run_type") == "aggregate":
        continue
    parts = b["name"].split("/")
    method = METHOD.get(parts[0])
    if method is None:
        continue
    n = int(parts[1])
    regions = n * (n + 1) // 2 + 1 if method == "graph" else n
    print(f"{method},{regions},{b['real_time'] * UNIT[b['time_unit']]:.6g}")
