"""Exact statistics over raw samples (ns), as the paper's Table 1 and beyond."""
import math


def table1(xs):
    """AVERAGE, AVEDEV (mean absolute deviation around the mean, as the spreadsheet function),
    MIN, MAX of a list of numbers; None for an empty list."""
    if not xs:
        return None
    n = len(xs)
    mean = sum(xs) / n
    return {"count": n, "average": mean, "avedev": sum(abs(x - mean) for x in xs) / n,
            "min": min(xs), "max": max(xs)}


def percentile(sorted_xs, p):
    """Nearest-rank percentile (the smallest sample with at least p % at or below it)."""
    if not sorted_xs:
        return None
    k = max(1, math.ceil(p / 100.0 * len(sorted_xs)))
    return sorted_xs[k - 1]


def long_run(xs):
    if not xs:
        return None
    s = sorted(xs)
    t = table1(xs)
    t.update({"p50": percentile(s, 50), "p99": percentile(s, 99), "p99_9": percentile(s, 99.9)})
    return t


def histogram(xs, bin_ns, nbins):
    """Counts per bin of bin_ns; the last bin collects everything at or above nbins*bin_ns."""
    h = [0] * (nbins + 1)
    for x in xs:
        i = int(x // bin_ns) if x >= 0 else 0
        h[min(i, nbins)] += 1
    return h


def rebin(hist, src_bin_ns, bin_ns, nbins):
    """Re-bins a histogram of src_bin_ns bins (its last bin = overflow) into bin_ns bins."""
    h = [0] * (nbins + 1)
    for i, c in enumerate(hist):
        if not c:
            continue
        if i == len(hist) - 1:
            h[nbins] += c
            continue
        j = int(i * src_bin_ns // bin_ns)
        h[min(j, nbins)] += c
    return h
