#!/usr/bin/env python3
"""The speed of `zcheck dataset verify` (not a test): frames per second on this machine for two
named workloads, against two yardsticks.

    PYTHONPATH=build/python /usr/bin/python3 bench/dataset_bench.py [--build build] [--models DIR]
                                                                     [--frames 96] [--runs 5]

Workloads (640x480, a ring of cameras around the mesh, transforms.json with 16-bit PNGs rendered
by the raster route, and a COLMAP model with float32 COLMAP depth maps):
  bunny     the Stanford bunny, 69,451 triangles
  terrain   builtin:terrain?n=709, 1,002,528 triangles

Yardsticks, each the median of --runs paired runs:
  loop      bench's dataset_loop: the same frames verified one after another by verifyMap in one
            process, the scene loaded, every map read and every camera made before the clock
            starts; the target is dataset verify's throughput >= 0.8x the loop's (reading and
            bookkeeping must not dominate). dataset verify is timed as a whole command and, for
            the ratio on the same footing as the loop, without its start-up (process, scene load,
            BVH build), measured as the same command on one frame (--shard 0/FRAMES) less that
            frame's own time.
  shards    two `--shard I/2 --threads 1` processes side by side against one `--threads 2`
            process: the target is >= 0.9x.
  diagnose  `--diagnose` on a dataset with no failing frame against without: only failing
            frames may pay for the diagnosis (the ratio should be ~1).
"""
import argparse
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "tests" / "python"))


def timed(argv, **kw):
    start = time.perf_counter()
    done = subprocess.run(argv, capture_output=True, text=True, **kw)
    seconds = time.perf_counter() - start
    if done.returncode not in (0, 1):
        sys.exit(f"{' '.join(map(str, argv))}: rc {done.returncode}\n{done.stderr}")
    return seconds, done


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--build", default=str(HERE.parent / "build"))
    parser.add_argument("--models", default=str(HERE.parent.parent / "shared" / "data" / "models"))
    parser.add_argument("--frames", type=int, default=96)
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--only", choices=["bunny", "terrain"])
    args = parser.parse_args()
    from dataset_maker import DatasetMaker

    zcheck = Path(args.build) / "cli" / "zcheck"
    loop = Path(args.build) / "bench" / "dataset_loop"
    # (mesh, the PNGs' steps per scene unit: millimetres for the bunny, whose depths are a few
    # tenths; the terrain's run to ~350 units, so 100 per unit fits 16 bits)
    workloads = {"bunny": (Path(args.models) / "stanford-bunny.obj", 1000.0), "terrain": ("builtin:terrain?n=709", 100.0)}
    print(f"zcheck dataset verify, {args.frames} frames at 640x480, median of {args.runs} paired runs")
    with tempfile.TemporaryDirectory(prefix="zcheck-dataset-bench-") as root:
        for name, (mesh, per_unit) in workloads.items():
            if args.only and name != args.only:
                continue
            maker = DatasetMaker(Path(root) / name, mesh, frames=args.frames, width=640, height=480)
            made = time.perf_counter()
            sources = {f"transforms (16-bit png, {per_unit:g} per unit)": (maker.transforms(per_unit=per_unit), ["--scale", str(per_unit)]),
                       "colmap (float32 maps)": (maker.colmap_text("colmap"),
                                                 ["--depth", str(maker.colmap_depth_maps("colmap_depth")) + "/{name}.geometric.bin"])}
            print(f"\n{name}: {maker.scene.triangle_count:,} triangles; dataset made in {time.perf_counter() - made:.1f} s")
            for label, (source, extra) in sources.items():
                base = [zcheck, "dataset", "verify", source, "--scene", mesh, "--quantity", "eye-z", *extra]
                command, steady, yardstick, shards, diagnosed = [], [], [], [], []
                for run in range(args.runs):
                    one = Path(root) / f"{name}-one.jsonl"
                    seconds_one, _ = timed(base + ["-o", one, "--threads", "2", "--shard", f"0/{args.frames}"])
                    import json
                    startup = seconds_one - json.loads(one.read_text().splitlines()[0])["seconds"]
                    one.unlink()
                    out = Path(root) / f"{name}-{run}.jsonl"
                    seconds, done = timed(base + ["-o", out, "--threads", "2"])
                    out.unlink()
                    command.append(args.frames / seconds)
                    steady.append(args.frames / (seconds - startup))
                    _, looped = timed([loop, source, "--scene", mesh, "--quantity", "eye-z", "--repeat", "1", *extra])
                    yardstick.append(float(looped.stdout.split()[-1]))
                    start = time.perf_counter()
                    procs = [subprocess.Popen(base + ["-o", Path(root) / f"{name}-s{i}.jsonl", "--threads", "1", "--shard", f"{i}/2"],
                                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL) for i in range(2)]
                    for p in procs:
                        p.wait()
                    shards.append(args.frames / (time.perf_counter() - start))
                    for i in range(2):
                        (Path(root) / f"{name}-s{i}.jsonl").unlink()
                    seconds_d, _ = timed(base + ["-o", out, "--threads", "2", "--diagnose"])
                    out.unlink()
                    diagnosed.append(args.frames / seconds_d)
                fps, fps_steady, fps_loop, fps_shards, fps_diag = map(statistics.median,
                                                                      (command, steady, yardstick, shards, diagnosed))
                print(f"  {label}")
                print(f"    dataset verify --threads 2   {fps:7.1f} frames/s  (runs {min(command):.1f}..{max(command):.1f}), "
                      f"{fps_steady:.1f} without its start-up")
                print(f"    loop over verifyMap          {fps_loop:7.1f} frames/s  ratio {fps_steady / fps_loop:.2f} "
                      f"(whole command {fps / fps_loop:.2f}; target >= 0.8: {'met' if fps_steady / fps_loop >= 0.8 else 'NOT met'})")
                print(f"    2 shards x --threads 1       {fps_shards:7.1f} frames/s  ratio {fps_shards / fps:.2f} (target >= 0.9: "
                      f"{'met' if fps_shards / fps >= 0.9 else 'NOT met'})")
                print(f"    --diagnose, nothing failing  {fps_diag:7.1f} frames/s  ratio {fps_diag / fps:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
