/// Plots of `meniscus validate` part B (app/validate_fluid.h): the matplotlib script and its run.

#include "app/plot_script.h"
#include "app/validate_fluid.h"

namespace meniscus::app {

namespace {

constexpr const char* PLOT_SCRIPT = R"PY(import json, math, os, sys
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
import matplotlib.ticker
out = sys.argv[1]
b = json.load(open(os.path.join(out, "results.json"))).get("part_b", {})

def damped_fit(r, t):
    """The fitted offset + e^{-gt}(A cos wt + B sin wt) of a B2/B4 run at times t."""
    w, g, c = r["omega"], r["decay_rate"], r["offset"]
    A, B = r["cos_coefficient"], r["sin_coefficient"]
    return [c + math.exp(-g * x) * (A * math.cos(w * x) + B * math.sin(w * x)) for x in t]

def save(fig, name):
    fig.tight_layout()
    fig.savefig(os.path.join(out, name), dpi=120)
    plt.close(fig)

def study_panel(ax, study, label, target):
    """|error| against the reference per resolution, one line per dt factor (log-log)."""
    factors = sorted({r["dt_factor"] for row in study["rows"] for r in row["runs"]}, reverse=True)
    for f in factors:
        xs, ys = [], []
        for row in study["rows"]:
            for r in row["runs"]:
                if r["dt_factor"] == f:
                    xs.append(row["resolution"])
                    ys.append(max(abs(r["relative_error"]) * 100, 1e-3))
        name = "own dt" if f == 1 else "dt/%g" % (1 / f)
        ax.loglog(xs, ys, "o-", ms=4, label="%s, %s" % (study["quantity"], name))
    ax.axhline(100 * target, color="k", ls=":", lw=1, label="target %g %%" % (100 * target))
    ax.set_xticks([row["resolution"] for row in study["rows"]])
    ax.xaxis.set_major_formatter(matplotlib.ticker.ScalarFormatter())
    ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    ax.set_xlabel(label)
    ax.set_ylabel("|error| (%)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)

def run_label(r, resolution_key, unit):
    f = r.get("dt_factor", 1)
    return "%d %s%s" % (r[resolution_key], unit, "" if f == 1 else ", dt/%g" % (1 / f))

if "B1" in b:
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(11, 4.5))
    for r in b["B1"]["runs"]:
        s = r["series"]
        scale = b["B1"]["velocity_scale"]
        ax.semilogy([1e3 * t for t in s["t"]], [max(u / scale, 1e-12) for u in s["max_speed"]],
                    label=run_label(r, "cells_per_diameter", "cells per D"))
    ax.set_xlabel("t (ms)")
    ax.set_ylabel("max|u| sqrt(rho D / sigma)")
    ax.set_title("B1 static drop: spurious currents")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    study_panel(bx, b["B1"]["jump"], "cells per diameter", 0.02)
    bx.set_title("B1 pressure jump error against 2 sigma / R")
    save(fig, "b1_spurious.png")

if "B2" in b:
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(12, 4.5))
    w0 = b["B2"]["lamb_omega"]
    for r in b["B2"]["runs"]:
        s = r["series"]
        t = s["t"]
        d = s["deformation"]
        ax.plot([1e3 * x for x in t], [1e3 * y for y in d], ".", ms=2,
                label="%s (measured)" % run_label(r, "cells_per_diameter", "cells per D"))
        w = r["omega"]
        ax.plot([1e3 * x for x in t], [1e3 * y for y in damped_fit(r, t)],
                "-", lw=1, label="fit: period %.2f ms" % (1e3 * 2 * math.pi / w))
        a0 = d[0] - r["offset"]
        ax.plot([1e3 * x for x in t], [1e3 * (r["offset"] + a0 * math.cos(w0 * x)) for x in t], "k:",
                lw=1)
    ax.plot([], [], "k:", label="Lamb: period %.2f ms" % (1e3 * 2 * math.pi / w0))
    ax.set_xlabel("t (ms)")
    ax.set_ylabel("a_x - (a_y + a_z)/2 (mm)")
    ax.set_title("B2 oscillating drop (l = 2)")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7)
    study_panel(bx, b["B2"]["frequency"], "cells per diameter", 0.02)
    bx.set_title("B2 frequency error against Lamb")
    save(fig, "b2_oscillation.png")

if "B3" in b:
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(11, 4.5))
    s0 = b["B3"]["theory_rate"]
    for r in b["B3"]["runs"]:
        s = r["series"]
        t = s["t"]
        R = b["B3"]["radius"]
        ax.semilogy([1e3 * x for x in t], [max(a / R, 1e-6) for a in s["amplitude"]], ".", ms=2,
                    label="measured (%s)" % run_label(r, "cells_per_wavelength", "cells per wavelength"))
        tf = [x for x in t if x <= r["fit_t_end"]]
        ap, am, rate = r["fit_a_plus"], r["fit_a_minus"], r["rate"]
        ax.semilogy([1e3 * x for x in tf], [(ap * math.exp(rate * x) + am * math.exp(-rate * x)) / R for x in tf],
                    "-", label="fit: s = %.1f 1/s" % rate)
    r = max(b["B3"]["runs"], key=lambda r: r["t_end"])
    t = r["series"]["t"]
    a0 = r["series"]["amplitude"][0]
    ax.semilogy([1e3 * x for x in t], [a0 * math.cosh(s0 * x) / R for x in t], "k:",
                label="theory a0 cosh(st): s = %.1f 1/s" % s0)
    ax.set_ylim(1e-3, 2)
    ax.set_xlabel("t (ms)")
    ax.set_ylabel("amplitude / R")
    ax.set_title("B3 Rayleigh-Plateau: perturbation amplitude")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=6)
    study_panel(bx, b["B3"]["growth"], "cells per wavelength", 0.05)
    bx.set_title("B3 growth rate error against theory")
    save(fig, "b3_growth.png")

if "B4" in b:
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(12, 4.5))
    w0 = b["B4"]["omega0"]
    for r in b["B4"]["runs"]:
        s = r["series"]
        t = s["t"]
        a = s["amplitude"]
        ax.plot(t, a, ".", ms=2, label="measured (%s)" % run_label(r, "cells_per_wavelength", "cells per wavelength"))
        ax.plot(t, damped_fit(r, t), "-", lw=1, label="fit: omega = %.3f" % r["omega"])
    r = b["B4"]["runs"][-1]
    t, a = r["series"]["t"], r["series"]["amplitude"]
    ax.plot(t, [a[0] * math.cos(w0 * x) for x in t], "k:", lw=1, label="inviscid: omega0 = %.3f" % w0)
    ax.set_xlabel("t")
    ax.set_ylabel("amplitude of cos(kx)")
    ax.set_title("B4 capillary wave")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=6)
    study_panel(bx, b["B4"]["frequency"], "cells per wavelength", 0.02)
    bx.set_title("B4 frequency error")
    save(fig, "b4_wave.png")

if "B5" in b:
    fig, ax = plt.subplots(figsize=(6, 4.5))
    for r in b["B5"]["runs"]:
        s = r["series"]
        v0 = s["inside_volume"][0]
        ax.plot([1e3 * x for x in s["t"]], [100 * (v / v0 - 1) for v in s["inside_volume"]], "o-", ms=2,
                label=r["scene"])
    ax.axhline(0.5, color="k", ls=":")
    ax.axhline(-0.5, color="k", ls=":")
    ax.set_xlabel("t (ms)")
    ax.set_ylabel("volume change of the enclosed phase (%)")
    ax.set_title("B5 merge and pinch scenes")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    save(fig, "b5_volume.png")
    studies = [r for r in b["B5"]["runs"] if "convergence" in r]
    if studies:
        # The time of the first topology change against the cells (at the own dt) and against dt
        # (at the scene's cells), relative to the finest value of each axis: no exact reference.
        fig, (ax, bx) = plt.subplots(1, 2, figsize=(11, 4.5))
        for r in studies:
            runs = r["convergence"]["runs"]
            space = sorted([v for v in runs if v["dt_factor"] == 1], key=lambda v: v["cells"])
            time = sorted([v for v in runs if v["cells_scale"] == 1], key=lambda v: -v["dt_factor"])
            order = r["convergence"].get("space_order")
            ax.plot([v["cells"] for v in space], [1e3 * v["event_time"] for v in space], "o-", ms=4,
                    label="%s%s" % (r["scene"], "" if order is None else " (order %.2g)" % order))
            order = r["convergence"].get("time_order")
            bx.semilogx([v["dt_factor"] for v in time], [1e3 * v["event_time"] for v in time], "o-",
                        ms=4, label="%s%s" % (r["scene"], "" if order is None else " (order %.2g)" % order))
        ax.set_xlabel("cells along the scene's x axis (own dt)")
        ax.set_ylabel("time of the first merge or pinch-off (ms)")
        ax.set_title("B5 topology change against resolution")
        bx.set_xlabel("dt factor (scene's cells)")
        bx.set_ylabel("time of the first merge or pinch-off (ms)")
        bx.set_title("B5 topology change against the time step")
        for a in (ax, bx):
            a.grid(True, which="both", alpha=0.3)
            a.legend(fontsize=7)
        save(fig, "b5_convergence.png")

if "B6" in b:
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(11, 4.5))
    B6 = b["B6"]
    w, g = B6["omega_exact"], B6["decay_rate_exact"]
    for r in B6["runs"]:
        s = r["series"]
        t, d = s["t"], s["deformation"]
        lbl = "%d cells per D, dt factor %g" % (r["cells_per_diameter"], r["dt_factor"])
        ax.plot([1e3 * x for x in t], [1e3 * y for y in d], ".", ms=2, label=lbl)
    r0 = B6["runs"][0]
    t = r0["series"]["t"]
    a0 = r0["series"]["deformation"][0] - r0["offset"]
    ax.plot([1e3 * x for x in t], [1e3 * (r0["offset"] + a0 * math.exp(-g * x) * math.cos(w * x)) for x in t],
            "k:", lw=1, label="exact mode: w = %.1f, g = %.1f 1/s" % (w, g))
    ax.set_xlabel("t (ms)")
    ax.set_ylabel("a_x - (a_y + a_z)/2 (mm)")
    ax.set_title("B6 viscous drop (l = 2)")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7)
    study_panel(bx, B6["frequency"], "cells per diameter", 0.05)
    study_panel(bx, B6["damping"], "cells per diameter", 0.05)
    bx.set_title("B6 errors against the exact mode")
    save(fig, "b6_viscous_drop.png")

if "B7" in b:
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(11, 4.5))
    B7 = b["B7"]
    for r in B7["runs"]:
        s = r["series"]
        ax.plot([1e3 * x for x in s["speed_t"]], [1e3 * u for u in s["speed"]], "-", lw=1,
                label="%d cells per D, %s, dt factor %g" % (r["cells_per_diameter"],
                                                            r.get("weights", "sharp"),
                                                            r["dt_factor"]))
        ax.axhline(1e3 * r["reference_speed"], color="k", ls=":", lw=1)
    ax.plot([], [], "k:", label="Hadamard-Rybczynski, wall-corrected")
    ax.set_xlabel("t (ms)")
    ax.set_ylabel("rise speed (mm/s)")
    ax.set_title("B7 creeping bubble")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7)
    study_panel(bx, B7["speed"], "cells per diameter", 0.05)
    for key, marker, name in (("speed_sharp", "^--", "sharp"),
                              ("speed_volume_fraction", "s--", "volume_fraction")):
        other = B7.get(key)
        if other and other["rows"]:
            bx.loglog([row["resolution"] for row in other["rows"]],
                      [max(abs(row["runs"][0]["relative_error"]) * 100, 1e-3)
                       for row in other["rows"]], marker, ms=4,
                      label="rise speed U, %s weights, own dt" % name)
    bx.legend(fontsize=7)
    bx.set_title("B7 rise speed error (pointwise weights unless marked)")
    save(fig, "b7_creeping_bubble.png")
)PY";

}  // namespace

std::string make_fluid_plots(const std::filesystem::path& out) {
    if (!run_plot_script(out, "plot_fluid.py", PLOT_SCRIPT, "plot_fluid_errors.txt"))
        return "**Part B plots failed** (see plot_fluid_errors.txt).";
    return "Part B plots: b1_spurious.png, b2_oscillation.png, b3_growth.png, b4_wave.png, "
           "b5_volume.png, b6_viscous_drop.png, b7_creeping_bubble.png (for the cases run).";
}

}  // namespace meniscus::app
