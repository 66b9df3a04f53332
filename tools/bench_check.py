#!/usr/bin/env python3
"""make bench-check: the few speed ratios a change must not lose, in about three minutes.

Absolute times drift with the machine and its load; a ratio to a reference measured in the same minutes
does not. Each check times orogen's side and its reference back to back (the minimum of a few
repetitions, the fairest figure on a shared machine), then compares the ratio with the one recorded in
docs/benchmarks.md's table "Ratio checks" and fails when it is worse than the recorded limit.

  export:gltf 4097²   the .glb written and synced, against `cp` + `sync` of the same file
  landscape step      BM_stream_power_fsl 1025², 1 thread (CPU), against fastscapelib's step on the same
                      model (the peer: $FSL_LEM or /work/peers-fsl/fsl_lem; skipped, said, when absent)
  1080p frame         BM_Frame1080p, against the calibration
  SPH step            BM_sph_step_dambreak, 2 threads, against the calibration
  default pipeline    `orogen run pipelines/default.orogen --no-cache`, against the calibration

The calibration is Diamond-Square at 4097² (bench_diamond_square): a plain memory-bound loop that has not
changed since it was written, so a frame that becomes 20 % slower against it became slower, whatever the
machine.

usage: tools/bench_check.py BUILD_DIR [--record]   (--record prints the table rows measured now)
"""
import json
import os
import re
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def bench(build, program, filt, reps=3, min_time=None, field='real_time'):
    """{run_name: minimum of `field` over repetitions, in ms} for `program`'s benchmarks matching `filt`."""
    exe = os.path.join(build, 'bench', program)
    if not os.path.exists(exe):
        raise SystemExit(f'bench-check: {exe} is missing; build it first (cmake --build {build} --target {program})')
    cmd = [exe, f'--benchmark_filter={filt}', f'--benchmark_repetitions={reps}', '--benchmark_format=json']
    if min_time:
        cmd.append(f'--benchmark_min_time={min_time}')
    out = subprocess.run(cmd, capture_output=True, text=True)
    if out.returncode != 0:
        raise SystemExit(f'bench-check: {" ".join(cmd)} failed:\n{out.stderr}')
    scale = {'ns': 1e-6, 'us': 1e-3, 'ms': 1.0, 's': 1e3}
    best = {}
    for r in json.loads(out.stdout)['benchmarks']:
        if r.get('run_type') != 'iteration':
            continue
        if r.get('error_occurred'):
            raise SystemExit(f'bench-check: {r["run_name"]}: {r.get("error_message")}')
        v = r[field] * scale[r.get('time_unit', 'ns')]
        best[r['run_name']] = min(best.get(r['run_name'], 1e30), v)
    if not best:
        raise SystemExit(f'bench-check: no benchmark of {program} matches {filt}')
    return best


def one(results, pattern):
    hits = [v for k, v in results.items() if re.search(pattern, k)]
    if len(hits) != 1:
        raise SystemExit(f'bench-check: expected one benchmark matching {pattern}, got {sorted(results)}')
    return hits[0]


def calibration(build):
    return one(bench(build, 'bench_diamond_square', 'BM_DiamondSquare/4097', reps=5), r'/4097(/|$)')


def fsl_peer_ms():
    """fastscapelib's step on its own model at 1025² (ms, its own timer, the best of 3 runs), or None."""
    exe = os.environ.get('FSL_LEM', '/work/peers-fsl/fsl_lem')
    if not os.access(exe, os.X_OK):
        return None
    best = None
    for _ in range(3):
        out = subprocess.run([exe, '1025', '10', '1'], capture_output=True, text=True)
        m = re.search(r'([0-9.]+)\s*ms\s*(?:per|/)\s*step', out.stdout + out.stderr)
        if out.returncode != 0 or not m:
            return None
        v = float(m.group(1))
        best = v if best is None else min(best, v)
    return best


def default_pipeline_ms(build):
    exe = os.path.join(build, 'bin', 'orogen')
    best = None
    for _ in range(2):
        t0 = time.monotonic()
        out = subprocess.run([exe, 'run', 'pipelines/default.orogen', '--no-cache', '--quiet', '--out',
                              os.path.join(build, 'bench-check-out')], cwd=ROOT, capture_output=True, text=True)
        if out.returncode != 0:
            raise SystemExit('bench-check: the default pipeline failed:\n' + out.stderr)
        t = (time.monotonic() - t0) * 1e3
        best = t if best is None else min(best, t)
    return best


def recorded():
    """{check: (recorded ratio, limit)} from docs/benchmarks.md's "Ratio checks" table."""
    text = open(os.path.join(ROOT, 'docs', 'benchmarks.md'), encoding='utf-8').read()
    m = re.search(r'## Ratio checks[^\n]*\n(?:(?!\|)[^\n]*\n)*((?:\|[^\n]*\n)+)', text)
    if not m:
        raise SystemExit('bench-check: docs/benchmarks.md has no "## Ratio checks" table')
    rows = {}
    for line in m.group(1).splitlines()[2:]:
        cells = [c.strip() for c in line.strip('|').split('|')]
        if len(cells) >= 3:
            num = lambda s: float(re.sub(r'[^0-9.]', '', s)) if re.search(r'[0-9]', s) else None
            rows[cells[0].strip('`')] = (num(cells[1]), num(cells[2]))
    return rows


def main():
    if len(sys.argv) < 2:
        print(__doc__)
        return 2
    build, record = sys.argv[1], '--record' in sys.argv
    rows = {} if record else recorded()  # read first: a table that does not parse fails before three minutes
    t_start = time.monotonic()
    cal = calibration(build)
    measured = {}  # check -> (ratio, how)
    g = bench(build, 'bench_export_gltf', 'BM_GltfGlb/4097/1|BM_GltfCopyFloor', reps=1)
    glb, floor = one(g, r'GltfGlb/4097/1(/|$)'), one(g, r'CopyFloor')
    measured['export:gltf 4097²'] = (glb / floor, f'{glb:.0f} ms against cp + sync {floor:.0f} ms')
    lem = one(bench(build, 'bench_stream_power', 'BM_stream_power_fsl/n:1025/steps:10/threads:1', reps=3,
                    field='cpu_time'), r'threads:1(/|$)') / 10.0
    peer = fsl_peer_ms()
    if peer:
        measured['landscape step'] = (lem / peer, f'{lem:.1f} ms a step against fastscapelib {peer:.0f} ms')
    else:
        measured['landscape step'] = (None, f'{lem:.1f} ms a step; fastscapelib not found (FSL_LEM), not compared')
    frame = one(bench(build, 'bench_render', 'BM_Frame1080p/1(/|$)', reps=3), r'Frame1080p/1(/|$)')
    measured['1080p frame'] = (frame / cal, f'{frame:.0f} ms against the calibration {cal:.1f} ms')
    sph = one(bench(build, 'bench_sph', 'BM_sph_step_dambreak/threads:2', reps=3), r'threads:2')
    measured['SPH step'] = (sph / cal, f'{sph:.1f} ms against the calibration {cal:.1f} ms')
    pipe = default_pipeline_ms(build)
    measured['default pipeline'] = (pipe / cal, f'{pipe / 1e3:.1f} s against the calibration {cal:.1f} ms')

    failed = 0
    print(f'{"check":20s} {"ratio":>8s} {"recorded":>9s} {"limit":>7s}  measured')
    for check, (ratio, how) in measured.items():
        rec, limit = rows.get(check, (None, None))
        bad = ratio is not None and limit is not None and ratio > limit
        failed += bad
        r = '—' if ratio is None else f'{ratio:.3g}'
        print(f'{check:20s} {r:>8s} {rec if rec is not None else "—":>9} {limit if limit is not None else "—":>7}  '
              f'{how}{"   <-- SLOWER THAN ITS LIMIT" if bad else ""}')
    print(f'bench-check: {time.monotonic() - t_start:.0f} s')
    if record:
        print('\nrows for docs/benchmarks.md (limit: 1.25x the recorded ratio unless a target says otherwise):')
        for check, (ratio, how) in measured.items():
            if ratio is not None:
                print(f'| {check} | {ratio:.3g} | {ratio * 1.25:.3g} | {how} |')
    if failed:
        print(f'bench-check: {failed} ratio(s) past their limit: see docs/benchmarks.md, "Ratio checks"')
        return 1
    return 0


if __name__ == '__main__':
    sys.exit(main())
