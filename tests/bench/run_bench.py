#!/usr/bin/env python3
"""Progressive-engine benchmarks (issue 3 figures), side by side with VTK where it is installed.

   python3 tests/bench/run_bench.py [--n 64] [--quick]   (scripts/bench.sh builds first)

For Harmonic N³ and for the real meshes in ../shared/datasets that have a point field:
  - pack time to 5% of the tets (whole pack, stream written) vs VTK 9.1's
    vtkUnstructuredGridQuadricDecimation to the same count; peak memory per input tet
  - field RMS / max error sampled at the original vertices at 5%, 10%, 30% of the tets, ours vs
    VTK; volume ratio (boundary preservation)
  - default pack: bits per tet and bytes per split vs zstd -19 of the raw arrays
  - decode + apply + local isosurface update, splits per second, native and wasm (node)
  - isovalue re-extraction, interval tree vs scan, at several levels (paper Table 1)
Writes build/bench/results.json and build/bench/results.md. Timings are single runs on this
machine (noted in the output); nothing here is asserted.
"""
import json
import os
import platform
import shutil
import subprocess
import sys
import tempfile

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
CLI = os.path.join(ROOT, "build/native/tetstream")
BENCH = os.path.join(ROOT, "build/native/tetstream_bench")
CHECK = os.path.join(ROOT, "build/native/tetstream_core_check")
CHECK_WASM = os.path.join(ROOT, "build/wasm/tetstream_core_check.js")
VTK_SCRIPT = os.path.join(ROOT, "tests/bench/vtk_decimate.py")
DATASETS = os.path.join(ROOT, "..", "shared", "datasets", "vtk-data")
OUT = os.path.join(ROOT, "build", "bench")


def run(cmd, **kw):
    r = subprocess.run(cmd, capture_output=True, text=True, **kw)
    if r.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed: {r.stderr.strip()}")
    return r.stdout


def run_json(cmd):
    return json.loads(run(cmd))


def have_vtk():
    return subprocess.run(["/usr/bin/python3", "-c", "import vtk"], capture_output=True).returncode == 0


def our_level(mesh, tmp, tets, field):
    """Our mesh with `tets` tetrahedra: the base of a pack stopped there (the collapse order does
    not depend on the target, so this is the stream's level with that many tets)."""
    d = os.path.join(tmp, f"ours-{tets}")
    r = run_json([CLI, "pack", mesh, "-o", d, "--field", field, "--base-fraction", "0", "--base-tets", str(tets), "--json"])
    out = d + ".vtu"
    run([CLI, "unpack", d, "--chunks", "1", "-o", out])
    return r, out


def bench_mesh(name, mesh, field, iso, tmp, with_vtk, quick):
    info = run_json([CLI, "info", mesh, "--json"])
    tets = info["tets"]
    res = {"name": name, "vertices": info["vertices"], "tets": tets, "field": field}
    # Pack time to 5% of the tets, and VTK's decimation to the same count.
    target = int(0.05 * tets)
    pack5, ours5 = our_level(mesh, tmp, target, field)
    res["pack5"] = {"ms": pack5["ms"], "simplifyMs": pack5["simplifyMs"], "peakMemoryMB": pack5["peakMemoryMB"],
                    "bytesPerInputTet": pack5["peakMemoryMB"] * 1048576 / tets, "tets": pack5["baseTets"]}
    levels = [0.05] if quick else [0.05, 0.10, 0.30]
    res["error"] = []
    for frac in levels:
        n = int(frac * tets)
        _, ours = (pack5, ours5) if frac == 0.05 else our_level(mesh, tmp, n, field)
        row = {"fraction": frac, "ours": run_json([BENCH, "error", mesh, ours, "--field", field])}
        if with_vtk:
            vtk_out = os.path.join(tmp, f"vtk-{n}.vtu")
            v = run_json(["/usr/bin/python3", VTK_SCRIPT, mesh, vtk_out, str(n), field])
            row["vtk"] = run_json([BENCH, "error", mesh, vtk_out, "--field", field])
            row["vtkSeconds"] = v["seconds"]
        res["error"].append(row)
    # The default pack: sizes against zstd -19 of the raw arrays.
    full = os.path.join(tmp, "full")
    p = run_json([CLI, "pack", mesh, "-o", full, "--field", field, "--json"])
    raw = os.path.join(tmp, "raw.bin")
    run([BENCH, "raw", mesh, raw])
    run(["zstd", "-19", "-q", "-f", raw, "-o", raw + ".zst"])
    res["size"] = {"bytes": p["bytes"], "bitsPerTet": p["bitsPerTet"], "bytesPerSplit": p["bytesPerSplit"],
                   "baseBytes": p["baseBytes"], "baseVertices": p["baseVertices"], "chunks": p["chunks"],
                   "zstd19RawBitsPerTet": 8 * os.path.getsize(raw + ".zst") / tets, "packMs": p["ms"]}
    # Streaming rates and re-extraction, native and wasm.
    res["stream"] = {"native": run_json([CHECK, "--stream", full, str(iso)])}
    if os.path.exists(CHECK_WASM):
        res["stream"]["wasm"] = run_json(["node", "--no-experimental-fetch", CHECK_WASM, "--stream", full, str(iso)])
    return res


def markdown(results, machine):
    lines = [f"Machine: {machine}. Single runs; times in ms unless noted.", ""]
    lines.append("| dataset | tets | pack to 5% (ms) | VTK decimation to 5% (ms) | ratio | peak memory / input tet |")
    lines.append("|---|---|---|---|---|---|")
    for r in results:
        vtk = next((e.get("vtkSeconds") for e in r["error"] if e["fraction"] == 0.05), None)
        vtk_ms = f"{vtk * 1000:.0f}" if vtk is not None else "n/a"
        ratio = f"{vtk * 1000 / r['pack5']['ms']:.2f}× {'faster' if vtk * 1000 > r['pack5']['ms'] else 'slower'}" if vtk else "n/a"
        lines.append(f"| {r['name']} | {r['tets']:,} | {r['pack5']['ms']:.0f} | {vtk_ms} | {ratio} | {r['pack5']['bytesPerInputTet']:.0f} B |")
    lines += ["", "| dataset | level (tets) | ours RMS / max (rel. to range) | VTK RMS / max | ours volume ratio | VTK volume ratio |",
              "|---|---|---|---|---|---|"]
    for r in results:
        for e in r["error"]:
            o, v = e["ours"], e.get("vtk")
            vtxt = f"{v['rmsRelative']:.5f} / {v['maxRelative']:.4f}" if v else "n/a"
            vvol = f"{v['volumeRatio']:.5f}" if v else "n/a"
            lines.append(f"| {r['name']} | {e['fraction']:.0%} ({o['tets']:,}) | {o['rmsRelative']:.5f} / {o['maxRelative']:.4f} | {vtxt} | {o['volumeRatio']:.5f} | {vvol} |")
    lines += ["", "| dataset | packed bits/tet | bytes/split | zstd -19 raw bits/tet | base | chunks |", "|---|---|---|---|---|---|"]
    for r in results:
        s = r["size"]
        lines.append(f"| {r['name']} | {s['bitsPerTet']:.1f} | {s['bytesPerSplit']:.1f} | {s['zstd19RawBitsPerTet']:.1f} | {s['baseVertices']:,} vertices, {s['baseBytes'] / 1024:.0f} KB | {s['chunks']} |")
    lines += ["", "| dataset | splits/s native (apply + local update) | wasm | undo splits/s native | wasm |", "|---|---|---|---|---|"]
    for r in results:
        n, w = r["stream"]["native"], r["stream"].get("wasm")
        lines.append(f"| {r['name']} | {n['splitsPerSecond']:,.0f} | {w['splitsPerSecond']:,.0f} | {n['undoSplitsPerSecond']:,.0f} | {w['undoSplitsPerSecond']:,.0f} |" if w else
                     f"| {r['name']} | {n['splitsPerSecond']:,.0f} | n/a | {n['undoSplitsPerSecond']:,.0f} | n/a |")
    lines += ["", "Isovalue re-extraction (interval tree / full scan, ms), native and wasm:", "",
              "| dataset | level (share of splits) | tets | isovalue | triangles | native tree / scan | wasm tree / scan |", "|---|---|---|---|---|---|---|"]
    for r in results:
        nat, was = r["stream"]["native"], r["stream"].get("wasm")
        for li, lv in enumerate(nat["levels"]):
            for ki, iv in enumerate(lv["isovalues"]):
                w = was["levels"][li]["isovalues"][ki] if was else None
                wtxt = f"{w['treeMs']:.2f} / {w['scanMs']:.2f}" if w else "n/a"
                lines.append(f"| {r['name']} | {lv['fraction']:.0%} | {lv['tets']:,} | {iv['isovalue']:.3g} | {iv['triangles']:,} | {iv['treeMs']:.2f} / {iv['scanMs']:.2f} | {wtxt} |")
    return "\n".join(lines) + "\n"


def main():
    n = 64
    quick = "--quick" in sys.argv
    if "--n" in sys.argv:
        n = int(sys.argv[sys.argv.index("--n") + 1])
    os.makedirs(OUT, exist_ok=True)
    with_vtk = have_vtk()
    if not with_vtk:
        print("bench: VTK not installed (apt-get install python3-vtk9): VTK columns are n/a")
    machine = f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, {platform.system()}"
    results = []
    with tempfile.TemporaryDirectory(prefix="tetstream-bench-") as tmp:
        h = os.path.join(tmp, "harmonic.vtu")
        run([CLI, "gen", "harmonic", "--n", str(n), "-o", h])
        cases = [(f"Harmonic {n}³", h, "harmonic", 0.2)]
        post = os.path.join(DATASETS, "post.vtk")
        if os.path.exists(post):
            cases.append(("post.vtk (real)", post, "Pressure", 1.0))
        for name, mesh, field, iso in cases:
            print(f"bench: {name}", flush=True)
            sub = os.path.join(tmp, name.split()[0])
            os.makedirs(sub, exist_ok=True)
            results.append(bench_mesh(name, mesh, field, iso, sub, with_vtk, quick))
    with open(os.path.join(OUT, "results.json"), "w") as f:
        json.dump({"machine": machine, "results": results}, f, indent=1)
    md = markdown(results, machine)
    with open(os.path.join(OUT, "results.md"), "w") as f:
        f.write(md)
    print(md)


if __name__ == "__main__":
    main()
