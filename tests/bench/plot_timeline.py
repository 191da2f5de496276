#!/usr/bin/python3
"""The loading timeline of the browser viewer over the simulated link, from build/bench/stream.json
(written by tests/bench/stream_bench.mjs): bytes received against the link's ideal, the level shown
(share of the splits applied), and the time between frames.

   /usr/bin/python3 tests/bench/plot_timeline.py [stream.json] [out.png]
"""
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
src = sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "build/bench/stream.json")
out = sys.argv[2] if len(sys.argv) > 2 else os.path.join(ROOT, "build/bench/timeline.png")
data = json.load(open(src))
rate = data["rateBytesPerSec"]
# One run per dataset: the first.
runs, seen = [], set()
for r in data["results"]:
    if r["dataset"] not in seen and r.get("samples"):
        seen.add(r["dataset"])
        runs.append(r)
fig, axes = plt.subplots(3, len(runs), figsize=(5.5 * len(runs), 7.5), sharex="col", squeeze=False)
for col, r in enumerate(runs):
    s = r["samples"]
    t = [x[0] / 1000 for x in s]
    # Bytes on the wire (program, manifest, chunks) by the time each response ended.
    ends = sorted((row[3], row[4]) for row in r["timeline"] if row[4])
    wt, wb, total = [0.0], [0.0], 0
    for end_ms, size in ends:
        wt += [end_ms / 1000, end_ms / 1000]
        wb += [total / 1048576, (total + size) / 1048576]
        total += size
    ax = axes[0][col]
    ax.plot(wt, wb, label="bytes received (responses completed)")
    end = r["completeMs"] / 1000
    ax.plot([0, r["bytes"] / rate], [0, r["bytes"] / 1048576], "--", color="grey", label="bytes ÷ bandwidth")
    ax.axvline(r["firstSurfaceMs"] / 1000, color="tab:green", lw=1, label=f"first surface {r['firstSurfaceMs'] / 1000:.2f} s")
    ax.axvline(end, color="tab:red", lw=1, label=f"complete {end:.2f} s")
    ax.set_ylabel("MB")
    ax.set_title(f"{r['dataset']}: {r['bytes'] / 1048576:.2f} MB at {rate * 8 / 1e6:.0f} Mbit/s, {data['latencyMs']} ms latency", fontsize=9)
    ax.legend(fontsize=7, loc="lower right")
    ax = axes[1][col]
    ax.plot(t, [100 * x[4] / x[5] if x[5] else 0 for x in s], color="tab:purple")
    ax.set_ylabel("splits applied (%)")
    ax = axes[2][col]
    ft = [x for x in r["frameTimes"] if x[0] / 1000 <= end + 0.5]
    ax.plot([x[0] / 1000 for x in ft], [x[1] for x in ft], ".", ms=3, color="tab:orange")
    ax.axhline(33, color="grey", lw=0.8, ls="--")
    ax.set_ylabel("frame interval (ms)")
    ax.set_xlabel("seconds since navigation")
    for a in axes[:, col]:
        a.grid(True, alpha=0.3)
fig.tight_layout()
fig.savefig(out, dpi=100)
print(f"wrote {out}")
