"""``greybox train``: fit a current model to logs and save it to a model file."""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from ..atomic import check_output_path
from ..errors import GreyboxError, ModelFileError
from ..evaluate.metrics import metrics_table
from ..models.persistence import load_model, save_model
from ..models.registry import MODEL_CLASSES, model_kind
from ._options import add_log_arguments, read_logs

#: Learned attributes that describe the fit rather than the model.
_FIT_INFO = ("effort_unit_", "sample_time_", "n_samples_fit_", "cost_", "n_evaluations_")

_SVR_UNITS = {"C_": "{E}", "epsilon_": "{E}", "gamma_": "1/(standardised unit)^2", "intercept_": "{E}",
              "cv_rmse_": "{E}"}

#: Units of the learned parameters per model kind, ``{E}`` standing for the effort unit (A or N).
_UNITS = {
    "coulomb": {"coulomb_pos_": "{E}", "coulomb_neg_": "{E}", "viscous_pos_": "{E} s/mm",
                "viscous_neg_": "{E} s/mm"},
    "stribeck": {"coulomb_": "{E}", "static_": "{E}", "v_s_": "mm/s", "viscous_": "{E} s/mm"},
    "lugre": {"sigma0_": "{E}/mm", "sigma1_": "{E} s/mm", "viscous_": "{E} s/mm", "coulomb_": "{E}",
              "static_": "{E}", "v_s_": "mm/s"},
    "gms": {"alpha_": "-", "k_": "{E}/mm", "C_": "mm/s", "sigma_": "{E} s/mm", "mu_": "{E} s/mm", "s0_": "mm",
            "s_inf_": "mm", "v_s_": "mm/s"},
    "svr": _SVR_UNITS,
    "gmssvr": _SVR_UNITS,
}
#: Units of the parameters every current model has.
_COMMON_UNITS = {"J_": "{E} s^2/mm", "offset_": "{E}"}

#: Command-line options that set a model hyperparameter: option -> (parameter, value from args).
_MODEL_OPTIONS = {
    "--offset": ("fit_offset", lambda args: True if args.offset else None),
    "--asymmetric": ("asymmetric", lambda args: True if args.asymmetric else None),
    "--elements": ("n_elements", lambda args: args.elements),
    "--seed": ("random_state", lambda args: args.seed),
}


def add_parser(subparsers) -> None:
    parser = subparsers.add_parser(
        "train",
        help="fit a current model to logs and save it",
        description="Read and prepare every training log as a separate run, fit the model to all runs, "
        "print the training error and the identified parameters, and save the model file.",
    )
    parser.add_argument("--model", required=True, choices=sorted(MODEL_CLASSES), help="model kind")
    parser.add_argument(
        "--train", required=True, nargs="+", metavar="LOG", help="training logs (CSV, Parquet, MCAP or EMPS .mat)"
    )
    parser.add_argument(
        "--stage2",
        nargs="+",
        metavar="LOG",
        help="gmssvr only: logs for the SVR stage; the GMS stage is then fitted on --train alone",
    )
    parser.add_argument("--out", required=True, metavar="MODEL", help="model file to write (.gbm)")
    parser.add_argument("--force", action="store_true", help="overwrite MODEL if it exists")
    model = parser.add_argument_group("model options")
    model.add_argument("--offset", action="store_true", help="also fit a constant effort offset")
    model.add_argument(
        "--asymmetric", action="store_true", help="separate Coulomb and viscous levels per direction (coulomb)"
    )
    model.add_argument("--elements", type=int, metavar="N", help="number of Maxwell-slip elements (gms, default 4)")
    model.add_argument("--seed", type=int, metavar="N", help="seed of the multi-start identification (lugre, gms)")
    model.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="set any model hyperparameter, e.g. --set n_starts=8 or --set C=2.0 (repeatable; VALUE is read as "
        "a JSON number, true, false or null, else as text)",
    )
    parser.add_argument("--quiet", action="store_true", help="no progress display during the identification")
    add_log_arguments(parser)
    parser.set_defaults(run=run)


def build_model(kind: str, args: argparse.Namespace):
    """Return an unfitted model of ``kind`` with the hyperparameters given on the command line.

    Raises
    ------
    GreyboxError
        If an option does not apply to the model kind.
    """
    model = MODEL_CLASSES[kind]()
    accepted = model.get_params(deep=False)
    params = {}
    for option, (name, value_of) in _MODEL_OPTIONS.items():
        value = value_of(args)
        if value is None:
            continue
        if name not in accepted:
            raise GreyboxError(f"option {option} does not apply to the {kind} model")
        params[name] = value
    for setting in args.set:
        name, sep, text = setting.partition("=")
        name = name.strip()
        if not sep or not name:
            raise GreyboxError(f"--set expects NAME=VALUE, got {setting!r}")
        if name not in accepted:
            raise GreyboxError(f"the {kind} model has no hyperparameter {name!r}; it has: {', '.join(sorted(accepted))}")
        try:
            params[name] = json.loads(text)
        except json.JSONDecodeError:
            params[name] = text
    return model.set_params(**params)


#: Arrays and lists longer than this are summarised by their shape, not printed.
_MAX_PRINTED = 12


def _format_value(value) -> str:
    if isinstance(value, np.ndarray):
        if value.size > _MAX_PRINTED:
            return f"<array of shape {value.shape}>"
        return "[" + ", ".join(f"{v:.6g}" for v in value.ravel()) + "]"
    if isinstance(value, (list, tuple, dict)) and len(value) > _MAX_PRINTED:
        return f"<{type(value).__name__} of {len(value)} items>"
    if isinstance(value, float):
        return f"{value:.6g}"
    return str(value)


def describe_parameters(model, prefix: str = "") -> list[str]:
    """Lines ``name = value unit`` of the identified parameters of a fitted model.

    A fitted model nested in another (the GMS stage of a GMS+SVR model) is
    listed below it, its names prefixed with the attribute name.
    """
    unit = getattr(model, "effort_unit_", "A")
    units = {**_COMMON_UNITS, **_UNITS.get(model_kind(model), {})}
    lines = []
    for name, value in vars(model).items():
        if not name.endswith("_") or name.startswith("_") or name in _FIT_INFO:
            continue
        if hasattr(value, "get_params"):
            lines += describe_parameters(value, prefix=f"{prefix}{name[:-1]}.")
            continue
        suffix = units.get(name, "").format(E=unit)
        lines.append(f"  {prefix + name[:-1]:<14} = {_format_value(value)} {suffix}".rstrip())
    return lines


def _fit(model, args: argparse.Namespace):
    """Fit ``model`` as the options say; return the paths and runs it was fitted on."""
    progress = None if args.quiet else True
    if args.stage2 and not hasattr(model, "fit_svr"):
        raise GreyboxError(f"option --stage2 does not apply to the {args.model} model")
    runs = read_logs(args, args.train)
    if not args.stage2:
        model.fit(runs, progress=progress)
        return list(args.train), runs
    second = read_logs(args, args.stage2)
    model.fit_gms(runs, progress=progress).fit_svr(second, progress=progress)
    return list(args.train) + list(args.stage2), runs + second


def run(args: argparse.Namespace) -> int:
    out = Path(args.out)
    check_output_path(out, overwrite=args.force, protect=list(args.train) + list(args.stage2 or ()),
                      error=ModelFileError, inputs_name="one of the training logs")
    model = build_model(args.model, args)
    started = time.perf_counter()
    paths, runs = _fit(model, args)
    elapsed = time.perf_counter() - started
    unit = runs[0].effort_unit
    print(f"trained {args.model} on {len(runs)} run(s), {sum(len(r) for r in runs)} samples, "
          f"effort in {unit}, in {elapsed:.1f} s")
    print(f"  {'run':<32} {'samples':>8} {'RMSE ' + unit:>10} {'RE %':>7}")
    predictions = [model.predict(run) for run in runs]
    for path, run, prediction in zip(paths, runs, predictions):
        table = metrics_table(run.effort, prediction)
        print(f"  {Path(path).name[-32:]:<32} {table['n']:>8d} {table['rmse']:>10.4g} {table['re']:>7.3f}")
    if len(runs) > 1:
        table = metrics_table(np.concatenate([r.effort for r in runs]), np.concatenate(predictions))
        print(f"  {'all runs':<32} {table['n']:>8d} {table['rmse']:>10.4g} {table['re']:>7.3f}")
    print("  (RE = RMSE / mean |effort|)")
    print("parameters:")
    for line in describe_parameters(model):
        print(line)
    save_model(model, out, overwrite=args.force)
    reloaded = load_model(out)
    if not all(np.array_equal(reloaded.predict(run), p) for run, p in zip(runs, predictions)):
        raise ModelFileError(f"{out}: the saved model does not reproduce the fitted model's predictions")
    print(f"wrote {out}")
    return 0
