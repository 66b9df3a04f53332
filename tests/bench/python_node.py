"""orogen.node() on a numpy array, many calls: what handing the inputs to the runner costs.

    PYTHONPATH=build/python /usr/bin/python3 tests/bench/python_node.py [--calls 100] [--size 1025]

Times `calls` calls of node("erode:thermal", a size² float32 array, iterations=1) after one warm-up
call (plugins loaded), and prints the total and the time per call. One iteration of thermal erosion is a
few milliseconds on 1025², so the rest of a call (writing the spec, checking it, handing the array in,
handing the result out) shows.
"""
import argparse
import time

import numpy as np

import orogen


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--calls", type=int, default=100)
    parser.add_argument("--size", type=int, default=1025)
    args = parser.parse_args()
    rng = np.random.default_rng(1)
    terrain = (rng.random((args.size, args.size)) * 100).astype(np.float32)
    orogen.node("erode:thermal", terrain, iterations=1)  # warm-up: plugins loaded
    start = time.perf_counter()
    for _ in range(args.calls):
        orogen.node("erode:thermal", terrain, iterations=1)
    total = time.perf_counter() - start
    print(f"{args.calls} calls of node('erode:thermal', {args.size}x{args.size} float32, iterations=1): "
          f"{total:.2f} s, {1000 * total / args.calls:.1f} ms per call")


if __name__ == "__main__":
    main()
