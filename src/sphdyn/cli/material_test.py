"""``sphdyn material-test``: one material driven along a strain path, its
parameters from the command line or a deck."""

from __future__ import annotations

import json
import sys

from .args import _threads, _writable_dir


def _param_value(text: str):
    """``true``/``false`` -> bool, a number -> float (SI units), else the text
    (a word such as ``linear_polynomial``, or a quantity with units, which
    the material's table checks)."""
    low = text.strip().lower()
    if low in ("true", "false"):
        return low == "true"
    try:
        return float(text)
    except ValueError:
        return text.strip()


def _material_params(name: str, params: dict, given: dict | None = None) -> dict:
    """Check ``--param`` values against the material's deck table.

    ``given``: the command line's text of each value (for the messages).
    Returns the values with the table's defaults filled in (SI, None
    dropped); raises ValueError with one ``--param`` line per problem, its
    fix written as ``--param key=value``.
    """
    from pydantic import ValidationError

    from ..deck.errors import explain
    from ..deck.introspect import is_model, strip_optional
    from ..deck.sections.material import NOT_PARAMETERS
    from ..materials import available_models, get_model

    if name not in available_models():
        raise ValueError(f"MODEL {name!r} is not a registered material model. Fix: use "
                         f"one of {', '.join(available_models())}, or --deck DECK "
                         f"--material {name}")
    schema = get_model(name).schema
    if schema is None:
        return params
    keys = tuple(k for k, info in schema.model_fields.items()
                 if k not in NOT_PARAMETERS and not is_model(strip_optional(info.annotation)))
    raw = {"name": "material-test", "model": name, **params}
    try:
        table = schema.model_validate(raw)
    except ValidationError as exc:
        lines = []
        for line in explain(exc, raw, schema, params=keys):
            key = line.split(":", 1)[0]
            shown = f" {key}={given[key]}" if given and key in given else (
                "" if key == "deck" else f" {key}")  # "deck": the values together
            lines.append(f"--param{shown}{line[len(key):]}")
        raise ValueError("\n".join(lines)) from None
    return table.values()


def _test_density(name: str, params: dict) -> float | None:
    """The material test's density when ``params`` give none: the model's
    ``test_density`` (:class:`~sphdyn.materials.registry.MaterialModel`;
    None for a fluid, whose state needs its own), else None."""
    from ..materials import available_models, get_model

    if "density" in params or name not in available_models():
        return None
    return get_model(name).test_density


def cmd_material_test(args) -> int:
    from ..materials import get_model  # noqa: F401  (registers the models)
    from ..materials.driver import COMPONENTS, drive

    _threads(1 if args.threads is None else args.threads)
    if (args.confinement is None) == (args.path == "triaxial"):
        raise ValueError("--confinement is required by --path triaxial and used by no "
                         "other path. Fix: give --confinement PRESSURE [Pa] with "
                         "--path triaxial only")
    if args.confinement is not None and not 0 <= args.confinement < float("inf"):
        raise ValueError(f"--confinement {args.confinement:g}: the confining pressure "
                         "must be >= 0. Fix: give a compressive pressure in Pa, e.g. 1e7")
    params = {}
    name = args.model
    if args.deck:
        from ..deck import load_deck

        deck = load_deck(args.deck, None)
        mats = {m.name: m for m in deck.material}
        if args.material not in mats:
            raise ValueError(f"--material: the deck has no material {args.material!r}; "
                             f"materials: {', '.join(mats)}")
        mat = mats[args.material]
        params = mat.values()
        if name and name != mat.model:
            raise ValueError(f"MODEL {name!r} differs from the deck material's "
                             f"model {mat.model!r}")
        name = mat.model
    if not name:
        raise ValueError("give MODEL or --deck DECK --material NAME")
    given = {}
    for item in args.param or []:
        key, sep, value = item.partition("=")
        if not sep:
            raise ValueError(f"--param {item!r}: write KEY=VALUE (SI units). Fix: e.g. "
                             "--param density=2400")
        params[key.strip()] = _param_value(value)
        given[key.strip()] = value
    rho = None if args.deck else _test_density(name, params)
    params = _material_params(name, params if rho is None else {**params, "density": rho},
                              given)
    if rho is not None:
        print(f"sphdyn: no density given; {rho:g} kg/m^3 assumed (a strain-driven "
              "material point's stress does not depend on it; --param density=... to "
              "change)", file=sys.stderr)
    _writable_dir(args.out, "--out")
    res = drive(name, params, args.path, strain=args.strain, rate=args.rate,
                n_steps=args.steps, confinement=args.confinement or 0.0, size=args.size,
                out=args.out)
    # the CSV's own columns and signs (tension positive), not the plot's axes
    strain_col, stress_col = res["columns"]
    y = res["stress"][:, COMPONENTS.index(stress_col)]
    k = int(abs(y).argmax())
    print(json.dumps({"model": name, "path": args.path, "peak_stress_Pa": float(y[k]),
                      "at_strain": float(res["strain"][k, COMPONENTS.index(strain_col)]),
                      "stress_column": f"stress_{stress_col}_Pa",
                      "strain_column": f"strain_{strain_col}",
                      "final_damage": float(res["damage"][-1]),
                      "files": [str(f) for f in res["files"]]}))
    return 0
