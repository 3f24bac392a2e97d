"""Plots of a result with matplotlib (optional: Debian python3-matplotlib, pip driftlab[plot])."""

from __future__ import annotations

import math
import os
from typing import Optional, Union

import numpy as np

from driftlab.results import COMPONENTS, Result


def _unit(component: str) -> str:
    if component.endswith("_m_per_s"):
        return "m/s"
    if component.endswith("_deg"):
        return "deg"
    return "m"


def plot_envelopes(result: Result, path: Union[str, os.PathLike],
                   title: Optional[str] = None) -> Union[str, os.PathLike]:
    """Per error component, the Monte-Carlo mean and the mean +- 1 sigma band over time, saved to
    ``path`` (format from the extension). With one run sigma is undefined (NaN) and only the mean
    is drawn. Units: m, m/s, deg as in the result."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    if len(result.t_s) == 0:
        raise ValueError("the result has no epochs")
    columns = 3
    rows = math.ceil(len(COMPONENTS) / columns)
    figure, axes = plt.subplots(rows, columns, figsize=(4.2 * columns, 2.6 * rows), sharex=True,
                                squeeze=False)
    for index in range(rows * columns):
        axis = axes[index // columns][index % columns]
        if index >= len(COMPONENTS):
            axis.set_visible(False)
            continue
        name = COMPONENTS[index]
        mean = result.mean[:, index]
        std = result.std[:, index]
        if not np.isnan(std).any():
            axis.fill_between(result.t_s, mean - std, mean + std, color="tab:blue", alpha=0.25,
                              linewidth=0, label="mean \u00b1 1\u03c3")
        axis.plot(result.t_s, mean, color="tab:blue", linewidth=1.2, label="mean")
        axis.axhline(0.0, color="0.6", linewidth=0.6)
        axis.set_title(name, fontsize=9)
        axis.set_ylabel(_unit(name), fontsize=8)
        axis.tick_params(labelsize=7)
        axis.grid(True, linewidth=0.3)
        if index + columns >= len(COMPONENTS):
            axis.set_xlabel("t [s]", fontsize=8)
            axis.xaxis.set_tick_params(labelbottom=True)
    axes[0][0].legend(fontsize=7, loc="upper left")
    figure.suptitle(title or f"{result.name or '(unnamed)'}: error envelopes over "
                    f"{result.run_count} runs (seed {result.seed})", fontsize=11)
    figure.tight_layout()
    figure.savefig(os.fspath(path), dpi=110)
    plt.close(figure)
    return path


def summary_lines(result: Result):
    """Text lines of the final epoch's statistics (mean, sigma, RMS per component) and the final
    checkpoint's CEP50/CEP95/2DRMS."""
    message = result.message
    lines = [f"{result.name or '(unnamed)'}: runs {message.first_run}.."
             f"{message.first_run + result.run_count - 1} of {result.runs}, seed {result.seed}, "
             f"final epoch t = {result.t_s[-1]:.3f} s"]
    for j, name in enumerate(COMPONENTS):
        lines.append(f"  {name:<26} mean {result.mean[-1, j]:>11.4e}  std "
                     f"{result.std[-1, j]:>11.4e}  rms {result.rms[-1, j]:>11.4e}")
    if result.checkpoints:
        last = result.checkpoints[-1]
        lines.append(f"  horizontal CEP50 {last.cep50_m:.4g} m, CEP95 {last.cep95_m:.4g} m, "
                     f"2DRMS {last.drms2_m:.4g} m")
    return lines
