/// Plots of `meniscus validate` part B (app/validate_fluid.h): the matplotlib script and its run.

#include "app/plot_script.h"
#include "app/validate_fluid.h"

namespace meniscus::app {

namespace {

constexpr const char* PLOT_SCRIPT = R"PY(import json, math, os, sys
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
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

if "B1" in b:
    fig, ax = plt.subplots(figsize=(6, 4.5))
    for r in b["B1"]["runs"]:
        s = r["series"]
        scale = b["B1"]["velocity_scale"]
        ax.semilogy([1e3 * t for t in s["t"]], [max(u / scale, 1e-12) for u in s["max_speed"]],
                    label="%d cells per D" % r["cells_per_diameter"])
    ax.set_xlabel("t (ms)")
    ax.set_ylabel("max|u| sqrt(rho D / sigma)")
    ax.set_title("B1 static drop: spurious currents")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    save(fig, "b1_spurious.png")

if "B2" in b:
    fig, ax = plt.subplots(figsize=(7, 4.5))
    w0 = b["B2"]["lamb_omega"]
    for r in b["B2"]["runs"]:
        s = r["series"]
        t = s["t"]
        d = s["deformation"]
        ax.plot([1e3 * x for x in t], [1e3 * y for y in d], ".", ms=2,
                label="%d cells per D (measured)" % r["cells_per_diameter"])
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
    save(fig, "b2_oscillation.png")

if "B3" in b:
    fig, ax = plt.subplots(figsize=(6, 4.5))
    s0 = b["B3"]["theory_rate"]
    for r in b["B3"]["runs"]:
        s = r["series"]
        t = s["t"]
        R = b["B3"]["radius"]
        ax.semilogy([1e3 * x for x in t], [max(a / R, 1e-6) for a in s["amplitude"]], ".", ms=2,
                    label="measured (%d cells per wavelength)" % r["cells_per_wavelength"])
        tf = [x for x in t if x <= r["fit_t_end"]]
        ap, am, rate = r["fit_a_plus"], r["fit_a_minus"], r["rate"]
        ax.semilogy([1e3 * x for x in tf], [(ap * math.exp(rate * x) + am * math.exp(-rate * x)) / R for x in tf],
                    "-", label="fit: s = %.1f 1/s" % rate)
        a0 = s["amplitude"][0]
        ax.semilogy([1e3 * x for x in t], [a0 * math.cosh(s0 * x) / R for x in t], "k:",
                    label="theory a0 cosh(st): s = %.1f 1/s" % s0)
    ax.set_ylim(1e-3, 2)
    ax.set_xlabel("t (ms)")
    ax.set_ylabel("amplitude / R")
    ax.set_title("B3 Rayleigh-Plateau: perturbation amplitude")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    save(fig, "b3_growth.png")

if "B4" in b:
    fig, ax = plt.subplots(figsize=(7, 4.5))
    w0 = b["B4"]["omega0"]
    for r in b["B4"]["runs"]:
        s = r["series"]
        t = s["t"]
        a = s["amplitude"]
        ax.plot(t, a, ".", ms=2, label="measured (%d cells per wavelength)" % r["cells_per_wavelength"])
        ax.plot(t, damped_fit(r, t), "-", lw=1, label="fit: omega = %.3f" % r["omega"])
        ax.plot(t, [a[0] * math.cos(w0 * x) for x in t], "k:", lw=1, label="inviscid: omega0 = %.3f" % w0)
    ax.set_xlabel("t")
    ax.set_ylabel("amplitude of cos(kx)")
    ax.set_title("B4 capillary wave")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7)
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
)PY";

}  // namespace

std::string make_fluid_plots(const std::filesystem::path& out) {
    if (!run_plot_script(out, "plot_fluid.py", PLOT_SCRIPT, "plot_fluid_errors.txt"))
        return "**Part B plots failed** (see plot_fluid_errors.txt).";
    return "Part B plots: b1_spurious.png, b2_oscillation.png, b3_growth.png, b4_wave.png, "
           "b5_volume.png (for the cases run).";
}

}  // namespace meniscus::app
