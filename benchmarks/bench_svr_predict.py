"""Time the compiled RBF expansion against scikit-learn's SVR.predict.

The samples are drawn at random, not in time order as in a log, so that few terms are left out
(:mod:`greybox.models.kernel.rbf`): the kernel's worst case. Prints one JSON line: n_samples, n_support,
sklearn_s, compiled_s, speedup, max_abs_diff (largest |difference| of the two predictions) and
max_abs_pred, plus threads (of the compiled expansion; libsvm uses one).

    python benchmarks/bench_svr_predict.py --n-samples 200000 --n-train 4000 --threads 1
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np
from sklearn.svm import SVR

from greybox.models.kernel.rbf import rbf_expansion


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n-samples", type=int, default=200_000, help="samples to predict")
    parser.add_argument("--n-train", type=int, default=4000, help="training samples (most become support vectors)")
    parser.add_argument("--n-features", type=int, default=2)
    parser.add_argument("--threads", type=int, default=None, help="threads of the compiled expansion (default: cores)")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()

    rng = np.random.default_rng(args.seed)
    X = rng.standard_normal((args.n_train, args.n_features))
    y = np.sin(2.0 * X[:, 0]) + 0.3 * X[:, -1] ** 2 + 0.05 * rng.standard_normal(args.n_train)
    gamma = 2.0
    svr = SVR(kernel="rbf", C=10.0, epsilon=0.005, gamma=gamma).fit(X, y)
    X_new = rng.standard_normal((args.n_samples, args.n_features))

    start = time.perf_counter()
    expected = svr.predict(X_new)
    sklearn_s = time.perf_counter() - start

    arguments = (svr.support_vectors_, svr.dual_coef_.ravel(), svr.intercept_[0], gamma)
    rbf_expansion(X_new[:100], *arguments, threads=args.threads)  # compiled (or loaded from the cache) first
    start = time.perf_counter()
    got = rbf_expansion(X_new, *arguments, threads=args.threads)
    compiled_s = time.perf_counter() - start

    print(json.dumps({
        "n_samples": args.n_samples,
        "n_support": int(svr.support_vectors_.shape[0]),
        "sklearn_s": round(sklearn_s, 4),
        "compiled_s": round(compiled_s, 4),
        "speedup": round(sklearn_s / compiled_s, 2),
        "max_abs_diff": float(np.max(np.abs(got - expected))),
        "max_abs_pred": float(np.max(np.abs(expected))),
        "threads": args.threads or "default",
    }))


if __name__ == "__main__":
    main()
