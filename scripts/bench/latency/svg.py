"""A small hand-written SVG plot: step histograms of several series on a log10 y axis."""
import math
from xml.sax.saxutils import escape

COLORS = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd"]


def histogram_svg(title, series, bin_ns, nbins, path, width=900, height=480):
    """series: list of (label, counts) with counts of length nbins+1 (last = overflow).
    Plots the fraction of samples per bin (log scale) against the lateness in us."""
    ml, mr, mt, mb = 70, 20, 40, 60
    pw, ph = width - ml - mr, height - mt - mb
    xmax_us = (nbins + 1) * bin_ns / 1000.0
    fracs = []
    for _, counts in series:
        total = sum(counts) or 1
        fracs.append([c / total for c in counts])
    nonzero = [f for fs in fracs for f in fs if f > 0]
    ymin_exp = math.floor(math.log10(min(nonzero))) if nonzero else -6
    ymin_exp = max(ymin_exp, -7)
    ymax_exp = 0

    def sx(us):
        return ml + pw * us / xmax_us

    def sy(frac):
        if frac <= 0:
            return mt + ph
        e = max(math.log10(frac), ymin_exp)
        return mt + ph * (ymax_exp - e) / (ymax_exp - ymin_exp)

    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" '
           f'font-family="sans-serif" font-size="12">',
           f'<rect width="{width}" height="{height}" fill="white"/>',
           f'<text x="{width / 2}" y="22" text-anchor="middle" font-size="15">{escape(title)}</text>']
    # axes and grid
    for e in range(ymin_exp, ymax_exp + 1):
        y = sy(10.0 ** e)
        out.append(f'<line x1="{ml}" y1="{y:.1f}" x2="{ml + pw}" y2="{y:.1f}" stroke="#ddd"/>')
        out.append(f'<text x="{ml - 6}" y="{y + 4:.1f}" text-anchor="end">1e{e}</text>')
    step = _nice_step(xmax_us / 10.0)
    v = 0.0
    while v <= xmax_us + 1e-9:
        x = sx(v)
        out.append(f'<line x1="{x:.1f}" y1="{mt}" x2="{x:.1f}" y2="{mt + ph}" stroke="#eee"/>')
        out.append(f'<text x="{x:.1f}" y="{mt + ph + 16}" text-anchor="middle">{v:g}</text>')
        v += step
    out.append(f'<rect x="{ml}" y="{mt}" width="{pw}" height="{ph}" fill="none" stroke="black"/>')
    out.append(f'<text x="{ml + pw / 2}" y="{height - 18}" text-anchor="middle">wake-up lateness (us), '
               f'bins of {bin_ns / 1000:g} us; last bin: {nbins * bin_ns / 1000:g} us and more</text>')
    out.append(f'<text transform="translate(16,{mt + ph / 2}) rotate(-90)" text-anchor="middle">'
               f'fraction of samples (log)</text>')
    for k, ((label, counts), fs) in enumerate(zip(series, fracs)):
        color = COLORS[k % len(COLORS)]
        pts = []
        for i, f in enumerate(fs):
            x0, x1 = sx(i * bin_ns / 1000.0), sx((i + 1) * bin_ns / 1000.0)
            y = sy(f)
            pts.append(f"{x0:.1f},{y:.1f}")
            pts.append(f"{x1:.1f},{y:.1f}")
        out.append(f'<polyline fill="none" stroke="{color}" stroke-width="1.5" points="{" ".join(pts)}"/>')
        ly = mt + 16 + 18 * k
        out.append(f'<line x1="{ml + pw - 250}" y1="{ly - 4}" x2="{ml + pw - 225}" y2="{ly - 4}" '
                   f'stroke="{color}" stroke-width="3"/>')
        out.append(f'<text x="{ml + pw - 220}" y="{ly}">{escape(label)} (n={sum(counts)})</text>')
    out.append("</svg>")
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")


def _nice_step(raw):
    if raw <= 0:
        return 1.0
    e = math.floor(math.log10(raw))
    for m in (1, 2, 5, 10):
        if m * 10 ** e >= raw:
            return m * 10 ** e
    return 10 ** (e + 1)
