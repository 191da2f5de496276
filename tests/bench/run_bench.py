#!/usr/bin/env python3
"""Progressive-engine benchmarks, side by side with VTK where it is installed (docs/benchmarks.md).

   python3 tests/bench/run_bench.py [--n 64] [--quick] [--repeat 5] [--large] [--huge] [--only TEXT]
   (scripts/bench.sh builds first; --only: the cases whose name contains TEXT)

For Harmonic N³ and for the real meshes in DATASETS (when present) that have a point field (post.vtk,
Blunt Fin, the kiefer bracket, and without --quick the carotid data; with --large also ironProt.vtk, 1.8M tets, for
the pack time and field error only, as each VTK run on it takes ~25 s; with --huge also Harmonic
128³, 12.3M tets, for the pack time, memory and the field error at 5%, one run each, as each takes
about a minute):
  - pack time to 5% of the tets (whole pack, stream written) vs VTK 9.1's
    vtkUnstructuredGridQuadricDecimation to the same count; peak memory per input tet
  - field RMS / max error sampled at the original vertices at 5%, 10%, 30% of the tets, ours vs
    VTK; volume ratio (boundary preservation)
  - default pack: bits per tet and bytes per split vs zstd -19 of the raw arrays
  - decode + apply + local isosurface update, splits per second, native and wasm (node)
  - isovalue re-extraction, interval tree vs scan, at several levels (paper Table 1)
  - isosurface extraction on the full mesh, ours vs VTK's vtkContourFilter
  - rate-distortion: field RMS error and isosurface distance against bytes received, at every
    chunk boundary of the default pack, and VTK's decimation at the same tet counts (its size:
    zstd -19 of the decimated mesh's raw arrays); plotted to build/bench/rate_distortion.png
Writes build/bench/results.json and build/bench/results.md. Times are medians of --repeat runs
(default 5: two-thread packs vary from minute to minute), with the machine noted in the
output; nothing here is asserted.
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
MODEL = os.path.join(ROOT, "build/native/tetstream_model_bench")
MODEL_WASM = os.path.join(ROOT, "build/wasm/tetstream_model_bench.js")
VTK_SCRIPT = os.path.join(ROOT, "tests/bench/vtk_decimate.py")
VTK_CONTOUR = os.path.join(ROOT, "tests/bench/vtk_contour.py")
# The real meshes (post.vtk, carotid.vtk, ...): a folder named by TETSTREAM_DATASETS; skipped when absent.
DATASETS = os.environ.get("TETSTREAM_DATASETS", os.path.join(ROOT, "datasets"))
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


def median(xs):
    xs = sorted(xs)
    return xs[len(xs) // 2] if len(xs) % 2 else 0.5 * (xs[len(xs) // 2 - 1] + xs[len(xs) // 2])


def zstd19_bytes(mesh, tmp):
    """Bytes of `zstd -19` on the mesh's raw arrays (float32 positions and fields, uint32 tets)."""
    raw = os.path.join(tmp, "raw.bin")
    run([BENCH, "raw", mesh, raw])
    run(["zstd", "-19", "-q", "-f", raw, "-o", raw + ".zst"])
    return os.path.getsize(raw + ".zst")


def rate_distortion(mesh, field, iso, full, tmp, with_vtk, points):
    """Field error and isosurface distance against bytes received, ours at chunk boundaries and
    VTK's decimation at the same tet counts."""
    with open(os.path.join(full, "manifest.json")) as f:
        chunks = json.load(f)["chunks"]
    total_tets = chunks[-1]["tets"]
    # Chunk counts spread over the stream (the base, then geometrically), up to 60% of the tets.
    ks = sorted({1} | {max(1, round(len(chunks) ** (i / (points - 1)))) for i in range(points)})
    rows = []
    for k in ks:
        c = chunks[k - 1]
        if k > 1 and c["tets"] > 0.6 * total_tets:
            break
        out = os.path.join(tmp, f"rd-{k}.vtu")
        run([CLI, "unpack", full, "--chunks", str(k), "-o", out])
        row = {"chunks": k, "tets": c["tets"], "bytes": sum(x["bytes"] for x in chunks[:k]),
               "ours": run_json([BENCH, "error", mesh, out, "--field", field]),
               "oursIso": run_json([BENCH, "isodist", mesh, out, "--field", field, "--value", str(iso)])}
        if with_vtk:
            v = os.path.join(tmp, f"rd-vtk-{k}.vtu")
            run_json(["/usr/bin/python3", VTK_SCRIPT, mesh, v, str(c["tets"]), field])
            row["vtkBytes"] = zstd19_bytes(v, tmp)
            row["vtk"] = run_json([BENCH, "error", mesh, v, "--field", field])
            row["vtkIso"] = run_json([BENCH, "isodist", mesh, v, "--field", field, "--value", str(iso)])
        rows.append(row)
    return rows


def as_vtu(mesh, tmp, name):
    """The mesh as our reader sees it (hexahedra and grids split into tets) as .vtu, in the order
    read, so that VTK's decimation gets the very same tetrahedra. Not a lossless pack unpacked:
    its stream order scatters neighbours and slows both tools, which no user's input does."""
    out = os.path.join(tmp, f"{name}.vtu")
    run([BENCH, "vtu", mesh, out])
    return out


def our_level(mesh, tmp, tets, field):
    """Our mesh with `tets` tetrahedra: the base of a pack stopped there (the collapse order does
    not depend on the target, so this is the stream's level with that many tets)."""
    d = os.path.join(tmp, f"ours-{tets}")
    r = run_json([CLI, "pack", mesh, "-o", d, "--field", field, "--base-fraction", "0", "--base-tets", str(tets), "--json"])
    out = d + ".vtu"
    run([CLI, "unpack", d, "--chunks", "1", "-o", out])
    return r, out


def bench_mesh(name, mesh, field, iso, tmp, with_vtk, quick, repeat, light=False):
    info = run_json([CLI, "info", mesh, "--json"])
    tets = info["tets"]
    res = {"name": name, "vertices": info["vertices"], "tets": tets, "field": field, "repeat": repeat}
    # Pack time to 5% of the tets (median of `repeat` packs), and VTK's decimation to the same
    # count, the runs alternating so that both tools meet the machine at the same speed (a shared
    # machine's speed drifts from hour to hour).
    target = int(0.05 * tets)
    packs, vtk5 = [], []
    for _ in range(repeat):
        packs.append(our_level(mesh, tmp, target, field))
        if with_vtk:
            vtk5.append(run_json(["/usr/bin/python3", VTK_SCRIPT, mesh, os.path.join(tmp, f"vtk-{target}.vtu"),
                                  str(target), field]))
    pack5, ours5 = packs[0]
    res["pack5"] = {"ms": median([p["ms"] for p, _ in packs]), "runsMs": [p["ms"] for p, _ in packs],
                    "simplifyMs": median([p["simplifyMs"] for p, _ in packs]), "peakMemoryMB": pack5["peakMemoryMB"],
                    "bytesPerInputTet": pack5["peakMemoryMB"] * 1048576 / tets, "tets": pack5["baseTets"]}
    levels = [0.05] if quick else [0.05, 0.10, 0.30]
    res["error"] = []
    for frac in levels:
        n = int(frac * tets)
        row = {"fraction": frac, "requestedTets": n}
        compare_at = n
        if with_vtk:
            vtk_out = os.path.join(tmp, f"vtk-{n}.vtu")
            runs = vtk5 if n == target else [run_json(["/usr/bin/python3", VTK_SCRIPT, mesh, vtk_out, str(n), field])]
            row["vtk"] = run_json([BENCH, "error", mesh, vtk_out, "--field", field])
            row["vtkIso"] = run_json([BENCH, "isodist", mesh, vtk_out, "--field", field, "--value", str(iso)])
            row["vtkSeconds"] = median([v["seconds"] for v in runs])
            row["vtkRunsSeconds"] = [v["seconds"] for v in runs]
            # VTK's decimation may stop well short of the request (it does on Blunt Fin): then
            # both are compared at the count VTK reached, not ours at a coarser level.
            if row["vtk"]["tets"] > 1.02 * n:
                compare_at = row["vtk"]["tets"]
                row["vtkStoppedShort"] = True
        _, ours = (pack5, ours5) if compare_at == target else our_level(mesh, tmp, compare_at, field)
        row["ours"] = run_json([BENCH, "error", mesh, ours, "--field", field])
        row["oursIso"] = run_json([BENCH, "isodist", mesh, ours, "--field", field, "--value", str(iso)])
        res["error"].append(row)
    if light:  # pack time and errors only
        return res
    # The default pack: sizes against zstd -19 of the raw arrays.
    full = os.path.join(tmp, "full")
    p = run_json([CLI, "pack", mesh, "-o", full, "--field", field, "--json"])
    res["size"] = {"bytes": p["bytes"], "bitsPerTet": p["bitsPerTet"], "bytesPerSplit": p["bytesPerSplit"],
                   "baseBytes": p["baseBytes"], "baseVertices": p["baseVertices"], "chunks": p["chunks"],
                   "zstd19RawBitsPerTet": 8 * zstd19_bytes(mesh, tmp) / tets, "packMs": p["ms"]}
    # pack --compact: the same levels, splits by kept vertex inside each chunk (one run).
    c = run_json([CLI, "pack", mesh, "-o", os.path.join(tmp, "compact"), "--field", field, "--compact", "--json"])
    res["size"]["compact"] = {"bytes": c["bytes"], "bitsPerTet": c["bitsPerTet"], "packMs": c["ms"],
                              "peakMemoryMB": c["peakMemoryMB"], "defaultPeakMemoryMB": p["peakMemoryMB"]}
    # Isosurface on the full mesh: ours (in-process extraction time of `tetstream iso`) and VTK.
    ours_iso = [run_json([CLI, "iso", mesh, "--field", field, "--value", str(iso), "--json"]) for _ in range(repeat)]
    res["iso"] = {"isovalue": iso, "triangles": ours_iso[0]["triangles"], "ms": median([r["ms"] for r in ours_iso])}
    if with_vtk:
        v = run_json(["/usr/bin/python3", VTK_CONTOUR, mesh, field, str(iso), str(repeat)])
        res["iso"]["vtkMs"] = 1000 * median(v["seconds"])
        res["iso"]["vtkTriangles"] = v["triangles"]
    res["rateDistortion"] = rate_distortion(mesh, field, iso, full, tmp, with_vtk, 4 if quick else 8)
    # Streaming rates and re-extraction, native and wasm.
    res["stream"] = {"native": run_json([CHECK, "--stream", full, str(iso)])}
    if os.path.exists(CHECK_WASM):
        res["stream"]["wasm"] = run_json(["node", "--no-experimental-fetch", CHECK_WASM, "--stream", full, str(iso)])
    # The refinement worker's whole model (surface, hull, deltas for the page), every chunk.
    res["stream"]["model"] = {"native": run_json([MODEL, full, "--everything", "--isovalue", str(iso)])}
    if os.path.exists(MODEL_WASM):
        res["stream"]["model"]["wasm"] = run_json(["node", "--no-experimental-fetch", MODEL_WASM, full, "--everything",
                                                   "--isovalue", str(iso)])
    return res


def markdown(results, machine):
    lines = [f"Machine: {machine}. Times are medians of {results[0]['repeat']} runs, in ms unless noted.", ""]
    lines.append("| dataset | tets | pack to 5% (ms; runs) | VTK decimation to 5% (ms; runs, alternating with ours) | ratio | peak memory / input tet |")
    lines.append("|---|---|---|---|---|---|")
    for r in results:
        e5 = next((e for e in r["error"] if e["fraction"] == 0.05), {})
        vtk = e5.get("vtkSeconds")
        vtk_runs = e5.get("vtkRunsSeconds", [])
        vtk_ms = f"{vtk * 1000:.0f}" if vtk is not None else "n/a"
        if len(vtk_runs) > 1:
            vtk_ms += f" ({min(vtk_runs) * 1000:.0f}–{max(vtk_runs) * 1000:.0f})"
        if e5.get("vtkStoppedShort"):
            vtk_ms += f" (stopped at {e5['vtk']['tets']:,} tets)"
        ours = r["pack5"]["ms"]
        ratio = "n/a" if not vtk else (f"{vtk * 1000 / ours:.1f}× faster" if vtk * 1000 > ours else f"{ours / (vtk * 1000):.1f}× slower")
        runs = r["pack5"]["runsMs"]
        ours_ms = f"{ours:.0f}" + (f" ({min(runs):.0f}–{max(runs):.0f})" if len(runs) > 1 else "")
        lines.append(f"| {r['name']} | {r['tets']:,} | {ours_ms} | {vtk_ms} | {ratio} | {r['pack5']['bytesPerInputTet']:.0f} B |")
    lines += ["", "Field error sampled at the original vertices; isosurface distance at the isovalue of the isosurface table below "
              "(mean of both ways, relative to the diagonal); quality is the mean 3/κ of the tets (1 = equilateral). "
              "Where VTK stopped short of the requested count, both are compared at the count VTK reached (marked *).", "",
              "| dataset | level (tets) | ours RMS / max (rel. to range) | VTK RMS / max | isosurface distance ours / VTK | ours volume ratio | VTK volume ratio | quality ours / VTK |",
              "|---|---|---|---|---|---|---|---|"]
    for r in results:
        for e in r["error"]:
            o, v = e["ours"], e.get("vtk")
            vtxt = f"{v['rmsRelative']:.5f} / {v['maxRelative']:.4f}" if v else "n/a"
            vvol = f"{v['volumeRatio']:.5f}" if v else "n/a"
            vq = f"{v['meanQuality']:.3f}" if v else "n/a"
            star = "*" if e.get("vtkStoppedShort") else ""
            iso = f"{e['oursIso']['meanRelative']:.2e} / " + (f"{e['vtkIso']['meanRelative']:.2e}" if "vtkIso" in e else "n/a")
            lines.append(f"| {r['name']} | {e['fraction']:.0%}{star} ({o['tets']:,}) | {o['rmsRelative']:.5f} / {o['maxRelative']:.4f} | {vtxt} | "
                         f"{iso} | {o['volumeRatio']:.5f} | {vvol} | {o['meanQuality']:.3f} / {vq} |")
    results = [r for r in results if "size" in r]  # (the --large and --huge cases stop after the errors)
    lines += ["", "Default pack (one run; `--compact`: splits by kept vertex inside each chunk):", "",
              "| dataset | packed bits/tet | bytes/split | zstd -19 raw bits/tet | base | chunks | --compact bits/tet (bytes) | pack ms / --compact | peak MB / --compact |",
              "|---|---|---|---|---|---|---|---|---|"]
    for r in results:
        s = r["size"]
        c = s["compact"]
        lines.append(f"| {r['name']} | {s['bitsPerTet']:.1f} | {s['bytesPerSplit']:.1f} | {s['zstd19RawBitsPerTet']:.1f} | {s['baseVertices']:,} vertices, {s['baseBytes'] / 1024:.0f} KB | {s['chunks']} | "
                     f"{c['bitsPerTet']:.1f} ({100 * (c['bytes'] / s['bytes'] - 1):+.1f}%) | {s['packMs']:.0f} / {c['packMs']:.0f} | {c['defaultPeakMemoryMB']:.0f} / {c['peakMemoryMB']:.0f} |")
    lines += ["", "| dataset | isosurface on the full mesh: triangles | tetstream (ms) | VTK vtkContourFilter (ms) | ratio |", "|---|---|---|---|---|"]
    for r in results:
        i = r["iso"]
        vtk = f"{i['vtkMs']:.1f}" if "vtkMs" in i else "n/a"
        ratio = f"{i['vtkMs'] / i['ms']:.1f}× faster" if "vtkMs" in i else "n/a"
        lines.append(f"| {r['name']} | {i['triangles']:,} | {i['ms']:.1f} | {vtk} | {ratio} |")
    lines += ["", "Rate–distortion (default pack; error relative to the field range, isosurface distance to the diagonal):", "",
              "| dataset | chunks | tets | KB received | field RMS | iso distance mean / max | VTK KB (zstd -19) | VTK field RMS | VTK iso distance mean / max |",
              "|---|---|---|---|---|---|---|---|---|"]
    for r in results:
        for x in r["rateDistortion"]:
            v = (f"{x['vtkBytes'] / 1024:.0f} | {x['vtk']['rmsRelative']:.5f} | {x['vtkIso']['meanRelative']:.5f} / {x['vtkIso']['maxRelative']:.4f}"
                 if "vtk" in x else "n/a | n/a | n/a")
            lines.append(f"| {r['name']} | {x['chunks']} | {x['tets']:,} | {x['bytes'] / 1024:.0f} | {x['ours']['rmsRelative']:.5f} | "
                         f"{x['oursIso']['meanRelative']:.5f} / {x['oursIso']['maxRelative']:.4f} | {v} |")
    lines += ["", "Decode + apply + local isosurface update, splits/s: with the interval tree kept up to date, "
              "and as the viewer streams (tree deferred until the level settles); undo with the tree; the refinement "
              "worker's whole model (surface, hull and the deltas for the page; tests/bench/model_bench.cpp).", "",
              "| dataset | native, tree kept | wasm, tree kept | native, viewer | wasm, viewer | undo native | undo wasm "
              "| worker model native | worker model wasm |",
              "|---|---|---|---|---|---|---|---|---|"]
    for r in results:
        n, w = r["stream"]["native"], r["stream"].get("wasm") or {}
        model = r["stream"].get("model", {})
        mn, mw = model.get("native") or {}, model.get("wasm") or {}
        cell = lambda d, k: f"{d[k]:,.0f}" if k in d else "n/a"
        lines.append(f"| {r['name']} | {cell(n, 'splitsPerSecond')} | {cell(w, 'splitsPerSecond')} | {cell(n, 'viewerSplitsPerSecond')} | "
                     f"{cell(w, 'viewerSplitsPerSecond')} | {cell(n, 'undoSplitsPerSecond')} | {cell(w, 'undoSplitsPerSecond')} "
                     f"| {cell(mn, 'withDeltaSplitsPerSecond')} | {cell(mw, 'withDeltaSplitsPerSecond')} |")
    lines += ["", "Isovalue re-extraction, ms, native and wasm: the viewer's surface found through the interval tree / "
              "through a test of every tet (the same surface bookkeeping) / the plain extractor (a bare triangle soup "
              "from every tet, for reference):", "",
              "| dataset | level (share of splits) | tets | isovalue | triangles | native tree / scan / plain | wasm tree / scan / plain |",
              "|---|---|---|---|---|---|---|"]
    for r in results:
        nat, was = r["stream"]["native"], r["stream"].get("wasm")
        for li, lv in enumerate(nat["levels"]):
            for ki, iv in enumerate(lv["isovalues"]):
                w = was["levels"][li]["isovalues"][ki] if was else None
                times = lambda d: f"{d['treeMs']:.2f} / {d['scanMs']:.2f} / {d['plainMs']:.2f}"
                lines.append(f"| {r['name']} | {lv['fraction']:.0%} | {lv['tets']:,} | {iv['isovalue']:.3g} | {iv['triangles']:,} | "
                             f"{times(iv)} | {times(w) if w else 'n/a'} |")
    return "\n".join(lines) + "\n"


def plot(results, path):
    """Field error and isosurface distance against KB received, ours and VTK, one colour a dataset."""
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("bench: matplotlib missing (apt-get install python3-matplotlib): no plot")
        return
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    results = [r for r in results if "rateDistortion" in r]
    for r, colour in zip(results, ["tab:blue", "tab:orange", "tab:green", "tab:red"]):
        rd = r["rateDistortion"]
        kb = [x["bytes"] / 1024 for x in rd]
        axes[0].plot(kb, [x["ours"]["rmsRelative"] for x in rd], "o-", color=colour, label=f"tetstream, {r['name']}")
        axes[1].plot(kb, [x["oursIso"]["meanRelative"] for x in rd], "o-", color=colour, label=f"tetstream, {r['name']}")
        vt = [x for x in rd if "vtk" in x]
        if vt:
            vkb = [x["vtkBytes"] / 1024 for x in vt]
            axes[0].plot(vkb, [x["vtk"]["rmsRelative"] for x in vt], "s--", color=colour, alpha=0.6, label=f"VTK decimation, {r['name']}")
            axes[1].plot(vkb, [x["vtkIso"]["meanRelative"] for x in vt], "s--", color=colour, alpha=0.6, label=f"VTK decimation, {r['name']}")
    for ax, title in zip(axes, ["field RMS error (relative to range)", "isosurface distance, mean (relative to diagonal)"]):
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("KB received (VTK: zstd -19 of the decimated mesh)")
        ax.set_title(title, fontsize=10)
        ax.grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    print(f"bench: wrote {path}")


def main():
    n = 64
    quick = "--quick" in sys.argv
    large = "--large" in sys.argv
    if "--n" in sys.argv:
        n = int(sys.argv[sys.argv.index("--n") + 1])
    repeat = int(sys.argv[sys.argv.index("--repeat") + 1]) if "--repeat" in sys.argv else (1 if quick else 5)
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
        fin = os.path.join(DATASETS, "bluntfinxyz.bin")
        if os.path.exists(fin):
            # PLOT3D: read by our reader, written out as .vtu so that VTK gets the very same tets.
            fin_vtu = as_vtu(fin, tmp, "bluntfin")
            cases.append(("Blunt Fin (real, PLOT3D)", fin_vtu, "density", 1.2))
        kiefer = os.path.join(DATASETS, "kiefer_dataset.vtu")
        if os.path.exists(kiefer):
            # Quadratic tets with cell data: VTK's decimation takes neither, so both get the mesh as
            # our reader makes it (the corner tets, the stress averaged to the vertices) as .vtu.
            kiefer_vtu = as_vtu(kiefer, tmp, "kiefer")
            cases.append(("kiefer bracket (real, FEA)", kiefer_vtu, "Equivalent (von-Mises) Stress (psi)", 4.0))
        carotid = os.path.join(DATASETS, "carotid.vtk")
        if os.path.exists(carotid) and not quick:
            # Structured points, split into tets by our reader; large enough (167,580 vertices)
            # to be simplified in two halves at once. As .vtu for VTK, like Blunt Fin.
            carotid_vtu = as_vtu(carotid, tmp, "carotid")
            cases.append(("carotid (real, structured points)", carotid_vtu, "scalars", 200.0))
        iron = os.path.join(DATASETS, "ironProt.vtk")
        if os.path.exists(iron) and large:
            # 68³ structured points split into 1,804,578 tets; as .vtu for VTK, like the carotid data.
            iron_vtu = as_vtu(iron, tmp, "ironProt")
            cases.append(("ironProt (real, structured points, --large)", iron_vtu, "scalars", 127.5, "large"))
        if "--huge" in sys.argv:
            # Seven times the largest real mesh here, for how both tools scale: one run each (about
            # a minute), the error at 5% only. Made when its turn comes (a 537 MB file).
            cases.append(("Harmonic 128³ (--huge, one run)", os.path.join(tmp, "harmonic-128.vtu"), "harmonic", 0.2, "huge"))
        if "--only" in sys.argv:  # the cases whose name contains this text
            only = sys.argv[sys.argv.index("--only") + 1].lower()
            cases = [c for c in cases if only in c[0].lower()]
        for name, mesh, field, iso, *kind in cases:
            huge = kind == ["huge"]
            if huge:
                run([CLI, "gen", "harmonic", "--n", "128", "-o", mesh])
            print(f"bench: {name}", flush=True)
            sub = os.path.join(tmp, "-".join(name.split()[:2]))
            os.makedirs(sub, exist_ok=True)
            results.append(bench_mesh(name, mesh, field, iso, sub, with_vtk, quick or huge, 1 if huge else repeat, bool(kind)))
    with open(os.path.join(OUT, "results.json"), "w") as f:
        json.dump({"machine": machine, "results": results}, f, indent=1)
    plot(results, os.path.join(OUT, "rate_distortion.png"))
    md = markdown(results, machine)
    with open(os.path.join(OUT, "results.md"), "w") as f:
        f.write(md)
    print(md)


if __name__ == "__main__":
    main()
