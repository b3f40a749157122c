"""Common campaign figures (PNG): histogram of a metric, metric versus a swept parameter, envelope of a
logged signal over all runs. Inputs are the campaign folder (or its results table)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from . import read_results, read_timeseries

UNITS = {"eulerint_deg_s": "EULERINT [deg·s]", "ise": "ISE", "isf": "ISF", "settling_s": "settling time [s]",
         "effort_abs": "∫Σ|u| dt", "effort_sq": "∫‖u‖² dt", "final_error": "final error",
         "alpha_deg": "Euler-axis error α [deg]"}


def _plt():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def _ok(table):
    rows = table.to_pylist()
    return [r for r in rows if r["status"] == "ok"], len(rows)


def label(name: str) -> str:
    if name.startswith("p:"):
        return name[2:]
    return UNITS.get(name, name)


def hist(source, metric: str, path: str | Path, bins: int = 30, title: str = "") -> Path:
    table = read_results(source) if isinstance(source, (str, Path)) else source
    ok, n = _ok(table)
    vals = np.array([r[metric] for r in ok], dtype=float)
    vals = vals[np.isfinite(vals)]
    plt = _plt()
    fig, ax = plt.subplots(figsize=(7, 4.5))
    ax.hist(vals, bins=bins, color="C0", edgecolor="white")
    if vals.size:
        for q, ls in ((50, "-"), (5, ":"), (95, ":")):
            ax.axvline(np.percentile(vals, q), color="k", ls=ls, lw=0.8)
    ax.set_xlabel(label(metric))
    ax.set_ylabel("runs")
    ax.set_title(title or f"{label(metric)}: {vals.size} finite values of {len(ok)} ok runs ({n} runs); "
                          f"lines: median, 5 %, 95 %", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return Path(path)


def metric_vs_param(source, param: str, metric: str, path: str | Path, title: str = "") -> Path:
    table = read_results(source) if isinstance(source, (str, Path)) else source
    col = param if param.startswith("p:") else f"p:{param}"
    rows = table.to_pylist()
    plt = _plt()
    fig, ax = plt.subplots(figsize=(7, 4.5))
    ok = [r for r in rows if r["status"] == "ok"]
    bad = [r for r in rows if r["status"] != "ok"]
    ax.plot([r[col] for r in ok], [r[metric] for r in ok], "o", ms=4, alpha=0.7, label=f"ok ({len(ok)})")
    if bad:
        ymin = np.nanmin([r[metric] for r in ok]) if ok else 0.0
        ax.plot([r[col] for r in bad], [ymin] * len(bad), "x", color="C3", label=f"failed ({len(bad)})")
    ax.set_xlabel(label(col))
    ax.set_ylabel(label(metric))
    ax.legend()
    ax.grid(True, alpha=0.3)
    ax.set_title(title or f"{label(metric)} vs {label(col)}", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return Path(path)


def envelope(out_dir: str | Path, signal: str, path: str | Path, runs=None, ylabel: str = "",
             title: str = "") -> Path:
    """Median, 5–95 % band and min–max band of ``signal`` over the runs with a time series."""
    out_dir = Path(out_dir)
    table = read_results(out_dir)
    ok = [r["run"] for r in table.to_pylist() if r["status"] == "ok"]
    runs = [r for r in (runs if runs is not None else ok)
            if (out_dir / "timeseries" / f"run-{r:06d}.parquet").exists()]
    if not runs:
        raise FileNotFoundError(f"no time series in {out_dir}/timeseries (run the campaign with timeseries)")
    series = [read_timeseries(out_dir, r) for r in runs]
    t = series[0]["time"]
    y = np.stack([s[signal] for s in series if len(s["time"]) == len(t)])
    plt = _plt()
    fig, ax = plt.subplots(figsize=(8, 4.5))
    ax.fill_between(t, y.min(0), y.max(0), color="C0", alpha=0.15, label="min–max")
    ax.fill_between(t, np.percentile(y, 5, 0), np.percentile(y, 95, 0), color="C0", alpha=0.35, label="5–95 %")
    ax.plot(t, np.median(y, 0), color="C0", lw=1.5, label="median")
    ax.set_xlabel("time [s]")
    ax.set_ylabel(ylabel or label(signal))
    ax.legend()
    ax.grid(True, alpha=0.3)
    ax.set_title(title or f"{label(signal)}: envelope of {y.shape[0]} runs", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return Path(path)
