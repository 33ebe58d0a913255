"""The Python front of the extension (texel/_front.py): real signatures,
help() that starts with the signature and the text, reprs for every result
type, files let go by close() / with."""
import inspect
import pydoc

import numpy as np
import pytest

import texel
import texel.experiment


def public_functions():
    for module in (texel, texel.experiment):
        for name in module.__all__:
            obj = getattr(module, name)
            if inspect.isfunction(obj):
                yield f"{module.__name__}.{name}", obj


def public_classes():
    for module in (texel, texel.experiment):
        for name in module.__all__:
            obj = getattr(module, name)
            if isinstance(obj, type) and not issubclass(obj, BaseException):
                yield f"{module.__name__}.{name}", obj


def test_every_public_name_is_a_python_function_or_class():
    for module in (texel, texel.experiment):
        for name in module.__all__:
            obj = getattr(module, name)
            assert inspect.isfunction(obj) or isinstance(obj, type), f"{module.__name__}.{name} is {type(obj)}"
    assert len(list(public_functions())) > 30


@pytest.mark.parametrize("name,fn", list(public_functions()), ids=lambda x: x if isinstance(x, str) else "")
def test_signature_and_help(name, fn):
    sig = inspect.signature(fn)
    text = pydoc.render_doc(fn, renderer=pydoc.plaintext)
    assert "PyCapsule" not in text
    first = text.splitlines()[2].strip()  # "Python Library Documentation: ..." then a blank line
    assert first.startswith(f"{fn.__name__}{str(sig)[:20]}"), first
    assert fn.__doc__ and not fn.__doc__.startswith(fn.__name__ + "(")  # the text, not a signature line


@pytest.mark.parametrize("name,cls", list(public_classes()), ids=lambda x: x if isinstance(x, str) else "")
def test_class_and_method_signatures(name, cls):
    if "__signature__" in vars(cls):  # constructible from Python (result types are not)
        inspect.signature(cls)
    for attr, member in vars(cls).items():
        if not attr.startswith("_") and inspect.isfunction(member):
            inspect.signature(member)


def test_the_stub_defaults_are_the_extensions():
    # Calling the extension with every stubbed default spelled out: a renamed
    # or dropped keyword in either raises TypeError.
    for name in ("render", "document", "device", "reference_names", "builtin_devices"):
        fn = getattr(texel, name)
        kwargs = {p.name: p.default for p in inspect.signature(fn).parameters.values()
                  if p.default is not inspect.Parameter.empty}
        getattr(texel._texel, name)(**kwargs)
    s = inspect.signature(texel.Staircase)
    texel._texel.Staircase(1.0, [0.1], **{p.name: p.default for p in s.parameters.values()
                                         if p.kind is inspect.Parameter.KEYWORD_ONLY})


def test_wrong_keywords_still_fail_loudly():
    with pytest.raises(TypeError):
        texel.render(central_pitch=10)


def test_reprs(tmp_path):
    m = texel.render(seed=3, dtype="float64")
    stair = texel.Staircase(1.0, [0.1])
    guided = texel.GuidedOptimizer()
    q = guided.next()
    objects = [
        stair, guided, q, q.a, texel.magnitude_spectrum(m, 0.0125), texel.encode(texel.render(seed=3)),
        texel.parse_bitstream(texel.encode(texel.render(seed=3)).bytes),
        texel.transcode(texel.document(seed=3)), texel.load_signal(m, spacing_mm=0.0125), texel.document(),
        texel.device(), texel.ConstantProfile(), texel.SineProfile(), texel.ValuesProfile([0.1, 0.2]),
        texel.PointsProfile([(0, 0), (1, 1)]), texel.SampledProfile(0.5, [0.0, 1.0]),
        texel.PsychometricObserver(), texel.Rater(), texel.Matcher((0.0, 0.0)),
        texel.Store(*_db(tmp_path)), texel.experiment.Presenter(),
    ]
    for o in objects:
        r = repr(o)
        assert " object at 0x" not in r, r
    assert "trials=0" in repr(stair) and "P=" in repr(objects[5]) and "bins" in repr(objects[4])


def _db(tmp_path):
    path = tmp_path / "r.db"
    texel.Store(path, mode="rw").close()
    return (path,)


def test_store_with_block_leaves_no_wal_or_shm(tmp_path):
    path = _db(tmp_path)[0]
    with texel.Store(path) as store:
        assert store.sessions() == [] and not store.closed
    assert store.closed
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.db"]


def test_version():
    assert texel.__version__.count(".") == 2 and all(p.isdigit() for p in texel.__version__.split("."))
