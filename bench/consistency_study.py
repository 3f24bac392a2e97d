#!/usr/bin/python3
"""Filter-consistency study on a result file of `driftlab run JOB --covariance`.

Usage:
  bench/consistency_study.py RESULT.json [RESULT.json ...]

The rule, fixed before looking at any result (the same as tests/support/bonferroni_checks.h):
5 epochs evenly spaced among the epochs after the start, ending at the last (index
ceil(j n / 5) - 1 for j = 1..5 over the n epochs after t = 0). At each of them:
  * for each of the 9 position, velocity and attitude components, the Monte-Carlo / predicted
    variance ratio s^2 / p^2 must lie in [chi2_{a/2}(N-1), chi2_{1-a/2}(N-1)] / (N-1), a = 0.05/45
    ((N-1) s^2 / p^2 ~ chi2(N-1) for N independent Gaussian runs; Papoulis & Pillai 8.3);
  * the N-run average NEES of the d-state position/velocity/attitude error must lie in
    [chi2_{a/2}(d N), chi2_{1-a/2}(d N)] / N, a = 0.05/5 (Bar-Shalom, Li & Kirubarajan 5.4.2).
Family-wise false-alarm rate <= 5 % for each family (Bonferroni). Prints one line per result and
exits 1 when any check fails. Needs Debian's python3-scipy (chi-square quantiles).
"""
import json
import math
import sys

from scipy.stats import chi2

COMPONENTS = 9
PICKS = 5
FAMILY_ALPHA = 0.05


def study(path):
    with open(path) as f:
        result = json.load(f)
    runs = int(result["run_count"])
    epochs = result["epochs"]
    predicted = result["covariance"]["epochs"]
    nees = result["filter_consistency"]["epochs"]
    dimension = int(result["filter_consistency"]["state_dimension"])
    candidates = list(range(1, len(epochs)))
    picks = [candidates[math.ceil(j * len(candidates) / PICKS) - 1] for j in range(1, PICKS + 1)]
    a_var = FAMILY_ALPHA / (PICKS * COMPONENTS)
    low = chi2.ppf(a_var / 2, runs - 1) / (runs - 1)
    high = chi2.ppf(1 - a_var / 2, runs - 1) / (runs - 1)
    a_nees = FAMILY_ALPHA / PICKS
    nees_low = chi2.ppf(a_nees / 2, dimension * runs) / runs
    nees_high = chi2.ppf(1 - a_nees / 2, dimension * runs) / runs
    ratios, nees_values, failures = [], [], []
    for e in picks:
        t = epochs[e]["t_s"]
        assert abs(predicted[e]["t_s"] - t) < 1e-9 and abs(nees[e]["t_s"] - t) < 1e-9
        for c in range(COMPONENTS):
            s = epochs[e]["components"][c]["std"]
            p = predicted[e]["sigma"][c]
            ratio = (s / p) ** 2
            ratios.append(ratio)
            if not low <= ratio <= high:
                failures.append(f"{epochs[e]['components'][c]['component']} at {t:g} s: {ratio:.3f}")
        value = float(nees[e]["average_nees"])
        nees_values.append(value)
        if not nees_low <= value <= nees_high:
            failures.append(f"NEES at {t:g} s: {value:.3f}")
    name = result["job"]["sensor"].get("preset", result["job"].get("name", path))
    times = ", ".join(f"{epochs[e]['t_s']:g}" for e in picks)
    print(f"{name}: {runs} runs, epochs {times} s; variance ratios {min(ratios):.3f}-"
          f"{max(ratios):.3f} in [{low:.3f}, {high:.3f}]; NEES {min(nees_values):.2f}-"
          f"{max(nees_values):.2f} in [{nees_low:.2f}, {nees_high:.2f}]; "
          + ("PASS" if not failures else "FAIL: " + "; ".join(failures)))
    return not failures


def main():
    if len(sys.argv) < 2:
        print(__doc__)
        return 2
    ok = all([study(path) for path in sys.argv[1:]])
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
