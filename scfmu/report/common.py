"""Helpers shared by the paper sections: campaign tables as rows, figure paths, small plots."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

def rows(table) -> list[dict]:
    """A campaign results table (pyarrow) as a list of dicts, sorted by run."""
    return sorted(table.to_pylist(), key=lambda r: r["run"])


def failed(rs: list[dict]) -> list[str]:
    return [f"run {r['run']}: {r['status']}: {r['message'][:200]}" for r in rs if r["status"] != "ok"]


def figure(ctx, name: str) -> tuple[Path, str]:
    """(absolute path to write, path relative to the report folder) of figures/<name>."""
    p = ctx.figures_dir / name
    return p, f"figures/{name}"


def plt():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt_
    return plt_


def save(fig, path: Path, dpi: int = 110) -> None:
    fig.tight_layout()
    fig.savefig(path, dpi=dpi)
    plt().close(fig)


def sweep_panels(path: Path, x, panels: list[tuple[str, dict]], xlabel: str, title: str, logx=False,
                 logy: tuple = (), marks: dict | None = None) -> None:
    """One panel per (ylabel, {legend label: y values}) against x; markers, grid, legend on every panel.
    ``logy``: indices of panels with a log y axis; ``marks``: {x value: text} vertical lines (defaults)."""
    p = plt()
    n = len(panels)
    cols = 2 if n > 1 else 1
    nrows = math.ceil(n / cols)
    fig, axs = p.subplots(nrows, cols, figsize=(5.2 * cols, 3.6 * nrows), squeeze=False)
    for i, (ylabel, series) in enumerate(panels):
        ax = axs[i // cols][i % cols]
        for lab, y in series.items():
            ls = "-" if "FO" in lab or not lab.startswith(("PD", "PID")) else "--"
            ax.plot(x, y, marker="o", ls=ls, label=lab)
        if marks:
            for xv, txt in marks.items():
                ax.axvline(xv, color="k", ls=":", lw=0.8, label=txt)
        ax.set_xlabel(xlabel)
        ax.set_ylabel(ylabel)
        if logx:
            ax.set_xscale("log")
        if i in logy:
            ax.set_yscale("log")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
    for j in range(n, nrows * cols):
        axs[j // cols][j % cols].axis("off")
    fig.suptitle(title, fontsize=10)
    save(fig, path)


def arr(rs: list[dict], key: str) -> np.ndarray:
    return np.array([r.get(key, math.nan) for r in rs], dtype=float)


def reported(package: str, name: str = "reported.json") -> dict:
    """A paper's reported numbers, shipped as data of its plug-in (``<package>/data/reported.json``, read
    through importlib.resources)."""
    import json
    from importlib import resources
    return json.loads((resources.files(package) / "data" / name).read_text(encoding="utf-8"))
