"""Claim 3: write and read a sweep dataset through xarray's h5netcdf and netcdf4 engines.

usage: python -P bench/independent/netcdf_io.py SWEEP.nc OUTDIR REPEATS        (warm: one process)
       python -P bench/independent/netcdf_io.py SWEEP.nc OUTDIR cold ENGINE     (one cold write + read)

Warm: the dataset is loaded into memory once; then REPEATS rounds, the engines' order
alternating, each writing OUTDIR/ENGINE.nc (to_netcdf(engine=...)) and reading it back fully
(open_dataset(engine=...).load(), closed), CPU (process_time) and wall (perf_counter) of
each; the first round (engine imports, caches) is reported apart. Then every file is read by
every engine and compared with the dataset: every variable's values bit for bit and
Dataset.identical (values, dims, coords, attrs).
Cold: a fresh process (xarray imported, untimed) times its first write and first read through
ENGINE: what one CLI call pays, the engine's import included. Prints one line of JSON.
"""
import json
import os
import sys
import time

import numpy as np
import xarray as xr

ENGINES = ("h5netcdf", "netcdf4")


def timed(fn):
    c0, w0 = time.process_time(), time.perf_counter()
    out = fn()
    return out, time.process_time() - c0, time.perf_counter() - w0


def write(ds, path, engine):
    if os.path.exists(path):
        os.remove(path)
    ds.to_netcdf(path, engine=engine)


def read(path, engine):
    with xr.open_dataset(path, engine=engine) as f:
        return f.load()


def same_bits(a, b):
    for name in set(a.variables) | set(b.variables):
        x, y = a.variables.get(name), b.variables.get(name)
        if x is None or y is None or x.dtype != y.dtype or x.shape != y.shape:
            return f"{name}: missing or dtype/shape"
        if x.dtype.kind in "fiucb" and np.asarray(x).tobytes() != np.asarray(y).tobytes():
            return f"{name}: values differ"
        if x.dtype.kind not in "fiucb" and not np.array_equal(np.asarray(x), np.asarray(y)):
            return f"{name}: values differ"
    return "same bits" if a.identical(b) else "same bits, not identical (attrs/encoding)"


def cold(src, outdir, engine):
    ds = xr.load_dataset(src)
    path = os.path.join(outdir, f"cold_{engine}.nc")
    _, cw, ww = timed(lambda: write(ds, path, engine))
    _, cr, wr = timed(lambda: read(path, engine))
    print(json.dumps({"engine": engine, "write_cpu": cw, "write_wall": ww, "read_cpu": cr, "read_wall": wr}))


def warm(src, outdir, repeats):
    ds = xr.load_dataset(src)
    print(f"{src}: {len(ds.data_vars)} data variables, {dict(ds.sizes)}, {os.path.getsize(src)} bytes")
    times = {(e, op): [] for e in ENGINES for op in ("write_cpu", "write_wall", "read_cpu", "read_wall")}
    for k in range(repeats + 1):
        for engine in ENGINES if k % 2 else ENGINES[::-1]:
            path = os.path.join(outdir, f"{engine}.nc")
            _, cw, ww = timed(lambda: write(ds, path, engine))
            _, cr, wr = timed(lambda: read(path, engine))
            if k == 0:
                print(f"first round {engine}: write {cw:.3f} s CPU ({ww:.3f} wall), read {cr:.3f} s CPU ({wr:.3f} wall)")
                continue
            for op, v in zip(("write_cpu", "write_wall", "read_cpu", "read_wall"), (cw, ww, cr, wr)):
                times[(engine, op)].append(v)
    for (engine, op), v in times.items():
        print(f"{engine:9s} {op:10s} median {1e3 * np.median(v):8.2f} ms  [{1e3 * min(v):.2f}-{1e3 * max(v):.2f}] of {len(v)}")
    import netCDF4
    for engine in ENGINES:
        path = os.path.join(outdir, f"{engine}.nc")
        with netCDF4.Dataset(path) as f:
            print(f"{engine}.nc: {os.path.getsize(path)} bytes, data model {f.data_model}, disk format {f.disk_format}")
    for written in ENGINES:
        for reader in ENGINES:
            back = read(os.path.join(outdir, f"{written}.nc"), reader)
            print(f"written by {written}, read by {reader}: {same_bits(ds, back)} against the dataset")


def main():
    src, outdir = sys.argv[1], sys.argv[2]
    os.makedirs(outdir, exist_ok=True)
    if sys.argv[3] == "cold":
        cold(src, outdir, sys.argv[4])
    else:
        warm(src, outdir, int(sys.argv[3]))


if __name__ == "__main__":
    main()
