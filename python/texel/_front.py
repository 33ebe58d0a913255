"""The Python front of the extension (texel._texel): signatures, reprs.

pybind11 functions carry no signature ``inspect`` can read, and ``help()``
shows them as methods of a PyCapsule. The package's stubs (``*.pyi``) already
state every public signature for type checkers, so they are the one place a
signature is written: at import each public function is wrapped in a plain
Python function that carries its stub signature and the extension's
docstring and calls the extension, and each stubbed method of an extension
class is wrapped the same way. A stub that drifts from the extension shows
as a TypeError where the tests call with keywords (tests/python: every
area), and test_front.py spells out every stubbed default of the functions
that take only defaults.

Reprs: every result type prints its main values (a table below), never a
bare ``<... object at 0x...>``.
"""

import ast
import inspect
import pathlib


class _Annotation(str):
    """A stub annotation kept as text, shown without quotes by inspect."""

    def __repr__(self):
        return str(self)


def _default(node):
    # Stub defaults are literals and simple arithmetic on them (1.0 / 512).
    return eval(compile(ast.Expression(node), "<stub>", "eval"), {"__builtins__": {}})  # noqa: S307


def _signature(fn: ast.FunctionDef, drop_self: bool) -> inspect.Signature:
    a = fn.args
    P = inspect.Parameter
    params = []
    positional = a.posonlyargs + a.args
    defaults = [None] * (len(positional) - len(a.defaults)) + list(a.defaults)
    for i, (arg, d) in enumerate(zip(positional, defaults)):
        if drop_self and i == 0:
            continue
        kind = P.POSITIONAL_ONLY if arg in a.posonlyargs else P.POSITIONAL_OR_KEYWORD
        params.append(P(arg.arg, kind, default=P.empty if d is None else _default(d), annotation=_ann(arg.annotation)))
    if a.vararg:
        params.append(P(a.vararg.arg, P.VAR_POSITIONAL, annotation=_ann(a.vararg.annotation)))
    for arg, d in zip(a.kwonlyargs, a.kw_defaults):
        params.append(P(arg.arg, P.KEYWORD_ONLY, default=P.empty if d is None else _default(d), annotation=_ann(arg.annotation)))
    if a.kwarg:
        params.append(P(a.kwarg.arg, P.VAR_KEYWORD, annotation=_ann(a.kwarg.annotation)))
    returns = _ann(fn.returns)
    return inspect.Signature(params, return_annotation=returns)


def _ann(node):
    return inspect.Parameter.empty if node is None else _Annotation(ast.unparse(node))


def _function(name, target, signature, module, qualname=None):
    def front(*args, **kwargs):
        return target(*args, **kwargs)

    front.__name__ = name
    front.__qualname__ = qualname or name
    front.__module__ = module
    front.__doc__ = target.__doc__
    front.__signature__ = signature
    return front


def _method(name, target, signature, module, qualname):
    def front(self, *args, **kwargs):
        return target(self, *args, **kwargs)

    front.__name__ = name
    front.__qualname__ = qualname
    front.__module__ = module
    front.__doc__ = target.__doc__
    front.__signature__ = signature
    return front


def stub_tree(stub: pathlib.Path) -> ast.Module:
    return ast.parse(stub.read_text(encoding="utf-8"), str(stub))


def apply(extension, module: str, stub: pathlib.Path, reprs: dict) -> dict:
    """Wraps `extension`'s stubbed functions and methods (see the banner);
    returns the module-level fronts by name. `reprs` maps class names to
    their __repr__."""
    fronts = {}
    for node in stub_tree(stub).body:
        if isinstance(node, ast.FunctionDef):
            target = getattr(extension, node.name, None)
            if callable(target):
                fronts[node.name] = _function(node.name, target, _signature(node, False), module)
        elif isinstance(node, ast.ClassDef):
            cls = getattr(extension, node.name, None)
            if not isinstance(cls, type) or issubclass(cls, BaseException):
                continue
            cls.__module__ = module
            for item in node.body:
                if not isinstance(item, ast.FunctionDef):
                    continue
                static = any(isinstance(d, ast.Name) and d.id == "staticmethod" for d in item.decorator_list)
                if item.name == "__init__":
                    cls.__signature__ = _signature(item, True)
                    continue
                if item.name.startswith("_") or item.name not in vars(cls):
                    continue
                target = getattr(cls, item.name)
                qualname = f"{node.name}.{item.name}"
                if static:
                    setattr(cls, item.name, staticmethod(_function(item.name, target, _signature(item, False), module, qualname)))
                else:
                    setattr(cls, item.name, _method(item.name, target, _signature(item, True), module, qualname))
            if node.name in reprs:
                cls.__repr__ = reprs[node.name]
    return fronts


# ------------------------------------------------------------------- reprs
def _fields(*names, label=None):
    """A repr listing `names` (attributes, shown with their values)."""

    def __repr__(self):
        parts = []
        for n in names:
            v = getattr(self, n)
            parts.append(f"{n}={v:.6g}" if isinstance(v, float) else f"{n}={v!r}")
        return f"<texel.{label or type(self).__name__} {' '.join(parts)}>"

    return __repr__


def _staircase(self):
    state = "finished" if self.finished else f"next={self.convergent_value:.6g}"
    return f"<texel.Staircase trials={self.trials} reversals={len(self.reversal_trials)}/{self.n_reversals} {state}>"


def _optimizer(self):
    e = self.estimate
    state = "finished" if self.finished else "running"
    return (f"<texel.{type(self).__name__} {self.comparisons}/{self.budget} comparisons, {state}, "
            f"estimate=({e.pitch_db:.6g} dB, {e.irregularity_db:.6g} dB)>")


def _spectrum(self):
    return (f"<texel.Spectrum {len(self.magnitude)} bins × {self.bin_cpm:.6g} cycles/mm "
            f"({self.samples} samples, nfft {self.nfft})>")


def _encode_result(self):
    flags = "" if self.irregularity_identifiable else ", irregularity not identifiable"
    return (f"<texel.EncodeResult P={self.central_pitch_db:.6g} dB I={self.irregularity_db:.6g} dB "
            f"L={self.texel_length_mm:.6g} mm C={self.coarse_strength:.3g} F={self.fine_strength:.3g}, "
            f"{len(self.bytes)} bytes, model distance {self.model_distance:.3g}{flags}>")


def _store(self):
    return f"<texel.Store {'closed' if self.closed else repr(self.path)}>"


def _list_profile(attr):
    def __repr__(self):
        values = getattr(self, attr)
        shown = ", ".join(map(repr, values[:4])) + (", …" if len(values) > 4 else "")
        return f"{type(self).__name__}({attr}=[{shown}]{'' if len(values) <= 4 else f'  # {len(values)}'})"

    return __repr__


REPRS = {
    "Staircase": _staircase,
    "MatchOptimizer": _optimizer,
    "GuidedOptimizer": _optimizer,
    "BayesOptimizer": _optimizer,
    "Spectrum": _spectrum,
    "EncodeResult": _encode_result,
    "Store": _store,
    "ValuesProfile": _list_profile("values"),
    "PointsProfile": _list_profile("points"),
    "SampledProfile": lambda s: f"SampledProfile(spacing_mm={s.spacing_mm!r}, values=[… {len(s.values)} values])",
    "PsychometricObserver": lambda s: f"<texel.PsychometricObserver p(1)={s.p_correct(1.0):.3g}>",
    "Matcher": lambda s: "<texel.Matcher (simulated matching participant)>",
    "Rater": lambda s: f"<texel.Rater expected(0 dB)={s.expected(0.0):.3g}>",
}
