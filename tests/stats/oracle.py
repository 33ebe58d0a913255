"""Independent oracle for tests/stats: reads a long-format CSV and prints the
statistic as JSON, computed with SciPy/NumPy only (no code shared with Texel).

  oracle.py ttest   CSV COL MU LEVEL
  oracle.py paired  CSV COL COL2 LEVEL
  oracle.py anova   CSV SUBJECT DV FACTOR [FACTOR2]
  oracle.py ellipse CSV X Y LEVEL
  oracle.py describe CSV COL

RM-ANOVA here is the classical univariate decomposition of the balanced
subject x A (x B) array of cell means (sums of squares of marginal means),
not Texel's contrast formulation; the Greenhouse-Geisser epsilon is computed
from the double-centred covariance matrix of the cells (Greenhouse & Geisser
1959; for the interaction, of the A x B interaction residual scores via the
Kronecker product of centring matrices). Exit status 3 if SciPy is missing,
so the calling test fails loudly rather than skipping.
"""
import csv
import json
import math
import sys

try:
    import numpy as np
    from scipy import stats
except ImportError as e:  # the test must FAIL, not skip: install python3-scipy
    print(f"oracle.py: {e}; install python3-scipy and python3-numpy "
          "(scripts/install-deps.sh)", file=sys.stderr)
    sys.exit(3)


def read(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    return rows


def num(s):
    s = s.strip()
    if s == "" or s.upper() in ("NA", "NAN"):
        return math.nan
    return float(s)


def ttest(path, col, mu, level):
    x = np.array([num(r[col]) for r in read(path)])
    x = x[~np.isnan(x)]
    res = stats.ttest_1samp(x, mu)
    n = len(x)
    sd = x.std(ddof=1)
    se = sd / math.sqrt(n)
    q = stats.t.ppf(0.5 + level / 2, n - 1)
    return {"n": n, "mean": x.mean(), "sd": sd, "se": se, "t": res.statistic, "df": n - 1,
            "p": res.pvalue, "ci_low": x.mean() - q * se, "ci_high": x.mean() + q * se,
            "cohen_d": (x.mean() - mu) / sd}


def paired(path, a, b, level):
    rows = read(path)
    x = np.array([num(r[a]) for r in rows])
    y = np.array([num(r[b]) for r in rows])
    keep = ~(np.isnan(x) | np.isnan(y))
    x, y = x[keep], y[keep]
    res = stats.ttest_rel(x, y)
    d = x - y
    n = len(d)
    sd = d.std(ddof=1)
    se = sd / math.sqrt(n)
    q = stats.t.ppf(0.5 + level / 2, n - 1)
    return {"n": n, "mean": d.mean(), "sd": sd, "t": res.statistic, "df": n - 1, "p": res.pvalue,
            "ci_low": d.mean() - q * se, "ci_high": d.mean() + q * se, "cohen_d": d.mean() / sd}




def gg_epsilon(y, proj):
    """y: subjects x cells; proj: cells x cells orthogonal projector onto the effect space."""
    s = np.cov(y, rowvar=False, ddof=1)
    sc = proj @ s @ proj
    k = round(np.trace(proj))
    return float(np.trace(sc) ** 2 / (k * np.trace(sc @ sc)))


def anova(path, subject, dv, factors):
    rows = read(path)
    subj = []
    levels = [[] for _ in factors]
    cells = {}
    for r in rows:
        v = num(r[dv])
        if math.isnan(v):
            continue
        if r[subject] not in subj:
            subj.append(r[subject])
        key = tuple(r[f] for f in factors)
        for i, f in enumerate(factors):
            if r[f] not in levels[i]:
                levels[i].append(r[f])
        cells.setdefault((r[subject],) + key, []).append(v)
    n = len(subj)
    shape = [n] + [len(l) for l in levels]
    y = np.zeros(shape)
    for (s, *key), vals in cells.items():
        idx = (subj.index(s),) + tuple(levels[i].index(k) for i, k in enumerate(key))
        y[idx] = np.mean(vals)
    out = []
    gm = y.mean()

    def effect(name, ss, df, sse, dfe, eps, applies):
        f = (ss / df) / (sse / dfe)
        p = stats.f.sf(f, df, dfe)
        pgg = stats.f.sf(f, df * eps, dfe * eps)
        out.append({"effect": name, "ss": ss, "df": df, "ss_error": sse, "df_error": dfe, "f": f, "p": p,
                    "partial_eta2": ss / (ss + sse), "gg_epsilon": eps, "p_gg": pgg,
                    "sphericity_applies": applies})

    def centring(k):
        return np.eye(k) - np.ones((k, k)) / k

    def mean_proj(k):
        return np.ones((k, k)) / k

    if len(factors) == 1:
        a = shape[1]
        ms = y.mean(axis=1)  # subject means
        ma = y.mean(axis=0)  # level means
        ss_a = n * ((ma - gm) ** 2).sum()
        resid = y - ms[:, None] - ma[None, :] + gm
        ss_e = (resid ** 2).sum()
        eps = gg_epsilon(y, centring(a)) if a > 2 else 1.0
        effect(factors[0], ss_a, a - 1, ss_e, (a - 1) * (n - 1), eps, a > 2)
    else:
        a, b = shape[1], shape[2]
        m_s = y.mean(axis=(1, 2))
        m_a = y.mean(axis=(0, 2))
        m_b = y.mean(axis=(0, 1))
        m_sa = y.mean(axis=2)
        m_sb = y.mean(axis=1)
        m_ab = y.mean(axis=0)
        ss_a = n * b * ((m_a - gm) ** 2).sum()
        ss_b = n * a * ((m_b - gm) ** 2).sum()
        ss_ab = n * ((m_ab - m_a[:, None] - m_b[None, :] + gm) ** 2).sum()
        ss_as = b * ((m_sa - m_s[:, None] - m_a[None, :] + gm) ** 2).sum()
        ss_bs = a * ((m_sb - m_s[:, None] - m_b[None, :] + gm) ** 2).sum()
        ss_tot = ((y - gm) ** 2).sum()
        ss_s = a * b * ((m_s - gm) ** 2).sum()
        ss_abs = ss_tot - ss_s - ss_a - ss_b - ss_ab - ss_as - ss_bs
        flat = y.reshape(n, a * b)
        pa = np.kron(centring(a), mean_proj(b))
        pb = np.kron(mean_proj(a), centring(b))
        pab = np.kron(centring(a), centring(b))
        effect(factors[0], ss_a, a - 1, ss_as, (a - 1) * (n - 1), gg_epsilon(flat, pa) if a > 2 else 1.0, a > 2)
        effect(factors[1], ss_b, b - 1, ss_bs, (b - 1) * (n - 1), gg_epsilon(flat, pb) if b > 2 else 1.0, b > 2)
        dab = (a - 1) * (b - 1)
        effect(factors[0] + ":" + factors[1], ss_ab, dab, ss_abs, dab * (n - 1),
               gg_epsilon(flat, pab) if dab > 1 else 1.0, dab > 1)
    return {"subjects": n, "effects": out}


def ellipse(path, xc, yc, level):
    rows = read(path)
    x = np.array([num(r[xc]) for r in rows])
    y = np.array([num(r[yc]) for r in rows])
    keep = ~(np.isnan(x) | np.isnan(y))
    x, y = x[keep], y[keep]
    n, p = len(x), 2
    s = np.cov(np.vstack([x, y]), ddof=1)
    t2 = p * (n - 1) / (n - p) * stats.f.ppf(level, p, n - p)
    w, v = np.linalg.eigh(s)  # ascending
    major = v[:, 1]
    ang = math.degrees(math.atan2(major[1], major[0]))
    if ang <= -90:
        ang += 180
    if ang > 90:
        ang -= 180
    return {"n": n, "mean_x": x.mean(), "mean_y": y.mean(), "cov_xx": s[0, 0], "cov_xy": s[0, 1],
            "cov_yy": s[1, 1], "t2_critical": t2, "semi_major": math.sqrt(w[1] * t2 / n),
            "semi_minor": math.sqrt(w[0] * t2 / n), "angle_deg": ang}


def describe(path, col):
    x = np.array([num(r[col]) for r in read(path)])
    x = x[~np.isnan(x)]
    n = len(x)
    sd = x.std(ddof=1)
    q = stats.t.ppf(0.975, n - 1)
    q1, med, q3 = np.percentile(x, [25, 50, 75])  # numpy default 'linear' = R type 7
    return {"n": n, "mean": x.mean(), "sd": sd, "sem": sd / math.sqrt(n), "min": x.min(), "q1": q1,
            "median": med, "q3": q3, "max": x.max(), "ci95_low": x.mean() - q * sd / math.sqrt(n),
            "ci95_high": x.mean() + q * sd / math.sqrt(n)}


def main():
    cmd, path = sys.argv[1], sys.argv[2]
    a = sys.argv[3:]
    if cmd == "ttest":
        r = ttest(path, a[0], float(a[1]), float(a[2]))
    elif cmd == "paired":
        r = paired(path, a[0], a[1], float(a[2]))
    elif cmd == "anova":
        r = anova(path, a[0], a[1], a[2:])
    elif cmd == "ellipse":
        r = ellipse(path, a[0], a[1], float(a[2]))
    elif cmd == "describe":
        r = describe(path, a[0])
    else:
        sys.exit(f"oracle.py: unknown command {cmd}")
    print(json.dumps(r, default=float))


main()
