"""The public API carries type hints (issue 9: `py.typed` and type hints on the public API): every
parameter and return of the analyses, the Model builders, the Result measures and the helpers."""
import inspect
from pathlib import Path

import mbdsim as mb

# parameter studies (mbdsim.studies) are typed separately by their module
NOT_HERE = {"Study", "load_study", "plot_study", "sensitivity"}


def public_callables():
    for name in mb.__all__:
        if name in NOT_HERE:
            continue
        obj = getattr(mb, name)
        if inspect.isfunction(obj):
            yield name, obj
        elif inspect.isclass(obj) and not issubclass(obj, (Exception, Warning)):
            for cls in obj.__mro__:
                if cls.__module__.startswith("mbdsim"):
                    for k, v in vars(cls).items():
                        if inspect.isfunction(v) and not k.startswith("_"):
                            yield f"{name}.{k}", v


def test_every_public_parameter_and_return_is_annotated():
    missing = []
    for qual, fn in public_callables():
        sig = inspect.signature(fn)
        for p in sig.parameters.values():
            if p.name not in ("self", "cls") and p.annotation is inspect.Parameter.empty:
                missing.append(f"{qual}({p.name})")
        if sig.return_annotation is inspect.Signature.empty:
            missing.append(f"{qual} -> ?")
    assert not missing, missing


def test_package_is_marked_typed():
    assert (Path(mb.__file__).parent / "py.typed").is_file()
