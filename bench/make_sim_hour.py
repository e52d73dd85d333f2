"""Writes a long realistic recording for the streaming benchmarks: vibmode's own simulator (a bus
in service on an ISO 8608 road, `vibmode simulate ... --format f32`) run in drives of `--chunk`
records of 10.24 s (seeds SEED, SEED+1, ...), the records concatenated into one raw f32 file
(+ JSON sidecar, the simulator's own). One hour at 20 kHz is 352 records, 2.02 GB; memory stays
at one drive.

    python3 bench/make_sim_hour.py OUT.f32 --vibmode target/release/vibmode [--minutes 60]
        [--params examples/city_bus.toml] [--fs 20000] [--seed 1] [--chunk 32]
"""
import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    ap.add_argument("--vibmode", default=os.path.join(root, "target/release/vibmode"))
    ap.add_argument("--params", default=os.path.join(root, "examples/city_bus.toml"))
    ap.add_argument("--minutes", type=float, default=60.0)
    ap.add_argument("--fs", type=int, default=20000)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--chunk", type=int, default=32)
    a = ap.parse_args()
    record_s = 10.24
    n_records = math.ceil(a.minutes * 60.0 / record_s)
    sidecar = None
    done = 0
    seed = a.seed
    with open(a.out, "wb") as out, tempfile.TemporaryDirectory() as tmp:
        while done < n_records:
            n = min(a.chunk, n_records - done)
            d = os.path.join(tmp, f"drive{seed}")
            r = subprocess.run(
                [a.vibmode, "simulate", a.params, "--records", str(n), "--fs", str(a.fs),
                 "--seed", str(seed), "--format", "f32", "--effects", "in-service", "-o", d],
                stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
            if r.returncode != 0:
                out.close()
                os.remove(a.out)
                sys.exit(f"vibmode simulate failed (exit {r.returncode}): {r.stderr.strip()}")
            for k in range(1, n + 1):
                path = os.path.join(d, f"record_{k:02d}.f32")
                if sidecar is None:
                    with open(path + ".json") as f:
                        sidecar = json.load(f)
                with open(path, "rb") as f:
                    shutil.copyfileobj(f, out)
            shutil.rmtree(d)
            done += n
            seed += 1
    with open(a.out + ".json", "w") as f:
        json.dump(sidecar, f)
    print(f"wrote {n_records} records of {record_s} s ({n_records * record_s:.1f} s) to {a.out}")


if __name__ == "__main__":
    main()
