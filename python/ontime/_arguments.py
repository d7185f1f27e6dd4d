"""Arguments of the wrong type named as OnTime names them.

pybind11 answers a call whose arguments match no signature with a TypeError that lists the
signatures ("incompatible function arguments"). Every function and method of the extension is
wrapped here so that such a call raises UsageError naming the first parameter at fault and what it
must be, as the command line and the numeric parameters (parameter 'NAME': RULE (got WHAT)) do;
with overloads, the one whose parameters the arguments match by number and name is meant. The
functions and classes written in Python are wrapped too, so that an argument too many, an unknown
keyword or a missing argument is a UsageError naming it rather than Python's TypeError. A class of
the extension that callers do not make (ontime.Action, ontime.State, ...) raises UsageError when
called. The check runs only after the call has raised TypeError: a valid call costs one Python
frame.
"""

import functools
import inspect
import numbers
import os
import re
from collections.abc import Mapping
from typing import Any, Callable, List, Optional, Tuple

_INCOMPATIBLE = re.compile(r"^[\w.]*\(\): incompatible (function|constructor) arguments")
_SIGNATURE = re.compile(r"^\s+\d+\. [\w.]*\((?P<parameters>.*)\)(?: -> .*)?$")


class _Parameter:
    def __init__(self, name: str, annotation: str, has_default: bool, keyword_only: bool):
        self.name = name
        self.annotation = annotation
        self.has_default = has_default
        self.keyword_only = keyword_only


def _split_top_level(text: str) -> List[str]:
    """`text` split at the commas outside brackets and quotes (a default may be a list)."""
    parts, depth, quote, start = [], 0, "", 0
    for index, char in enumerate(text):
        if quote:
            if char == quote:
                quote = ""
        elif char in "'\"":
            quote = char
        elif char in "[({":
            depth += 1
        elif char in "])}":
            depth -= 1
        elif char == "," and depth == 0:
            parts.append(text[start:index].strip())
            start = index + 1
    if text[start:].strip():
        parts.append(text[start:].strip())
    return parts


def _parameters(signature: str) -> Optional[List[_Parameter]]:
    parameters, keyword_only = [], False
    for part in _split_top_level(signature):
        if part == "*":
            keyword_only = True
            continue
        if part.startswith("**") or part.startswith("*"):
            continue
        name, colon, rest = part.partition(":")
        if not colon:
            return None
        annotation, equals, _ = rest.partition("=")
        parameters.append(_Parameter(name.strip(), annotation.strip(), bool(equals), keyword_only))
    if parameters and parameters[0].name == "self":
        parameters = parameters[1:]
    return parameters


def _split_generic(annotation: str) -> Tuple[str, List[str]]:
    """`List[float]` as ("List", ["float"])."""
    if not annotation.endswith("]") or "[" not in annotation:
        return annotation, []
    head, _, inner = annotation.partition("[")
    return head, _split_top_level(inner[:-1])


def _class_named(annotation: str) -> Optional[type]:
    from . import _ontime
    module = _ontime
    path = annotation.split(".")
    if path[:2] == ["ontime", "_ontime"]:
        path = path[2:]
    for part in path:
        module = getattr(module, part, None)
        if module is None:
            return None
    return module if isinstance(module, type) else None


def _fits(value: Any, annotation: str) -> Optional[bool]:
    """Whether pybind11 could take `value` for `annotation`; None when this cannot tell."""
    head, arguments = _split_generic(annotation)
    if head in ("object", "Any", "kwargs", "args"):
        return True
    if head == "numpy.ndarray":
        if value is None or isinstance(value, (str, bytes, Mapping)):
            return False
        import numpy
        try:
            numpy.asarray(value, dtype=float)
        except (TypeError, ValueError):
            return False
        return None
    if head == "sequence":
        return not isinstance(value, (str, bytes, Mapping)) and hasattr(value, "__len__") and \
            hasattr(value, "__getitem__")
    if head == "str":
        return isinstance(value, str)
    if head == "bool":
        return isinstance(value, bool) or type(value).__name__ == "bool_"
    if head == "int":
        # A numpy array has __index__ too, but holds several numbers.
        return not isinstance(value, bool) and hasattr(value, "__index__") and not hasattr(value, "__len__")
    if head == "float":
        # A numpy scalar has __float__; an array has it too, but holds several numbers.
        return (not isinstance(value, (bool, str, bytes))) and (isinstance(value, numbers.Real) or (
            hasattr(value, "__float__") and not hasattr(value, "__len__")))
    if head == "os.PathLike":
        return isinstance(value, (str, os.PathLike))
    if head == "Optional" and len(arguments) == 1:
        return True if value is None else _fits(value, arguments[0])
    if head in ("List", "Sequence") and len(arguments) == 1:
        if isinstance(value, (str, bytes, Mapping)) or not hasattr(value, "__len__") or \
                not hasattr(value, "__getitem__"):
            return False
        results = [_fits(item, arguments[0]) for item in value]
        return False if False in results else (None if None in results else True)
    if head == "Dict" and len(arguments) == 2:
        if not isinstance(value, Mapping):
            return False
        results = [_fits(key, arguments[0]) for key in value] + [_fits(item, arguments[1])
                                                                 for item in value.values()]
        return False if False in results else (None if None in results else True)
    if head == "Callable":
        return callable(value)
    cls = _class_named(head)
    return isinstance(value, cls) if cls is not None else None


def _describe(annotation: str) -> str:
    head, arguments = _split_generic(annotation)
    simple = {"str": "a str", "bool": "a bool (True or False)", "int": "a whole number (int)",
              "float": "a number (int or float)", "os.PathLike": "a path (str or os.PathLike)",
              "Callable": "callable"}
    if head in simple:
        return simple[head]
    if head == "sequence":
        return "a list"
    if head == "numpy.ndarray":
        return "an array of numbers (a list or a numpy array)"
    if head == "Optional" and len(arguments) == 1:
        return f"{_describe(arguments[0])} or None"
    if head in ("List", "Sequence") and len(arguments) == 1:
        return f"a list whose items are each {_describe(arguments[0])}"
    if head == "Dict" and len(arguments) == 2:
        return f"a dict from {_describe(arguments[0])} to {_describe(arguments[1])}"
    name = head.rsplit(".", 1)[-1]
    return ("an " if name[:1].lower() in "aeiou" else "a ") + name


def _shown(value: Any) -> str:
    if value is None:
        return "None"
    if isinstance(value, bool):
        return "a bool"
    if isinstance(value, (int, float)):
        return repr(value)
    return "a " + type(value).__name__


def _arity_error(parameters: List[_Parameter], args: tuple, kwargs: dict, any_keyword: bool,
                 any_positional: bool = False) -> Tuple[Optional[Exception], dict]:
    """UsageError for arguments that match no parameter or leave one without a value (else None),
    and the arguments by parameter name."""
    from . import UsageError
    positional = [parameter for parameter in parameters if not parameter.keyword_only]
    if len(args) > len(positional) and not any_positional:
        return UsageError(f"takes at most {len(positional)} positional arguments ({len(args)} given)"), {}
    given = {parameter.name: value for parameter, value in zip(positional, args)}
    known = {parameter.name for parameter in parameters}
    for name, value in kwargs.items():
        if name in given:
            return UsageError(f"parameter '{name}' given twice"), given
        if name not in known and not any_keyword:
            return UsageError(f"unknown parameter '{name}'"), given
        given[name] = value
    for parameter in parameters:
        if parameter.name not in given and not parameter.has_default:
            return UsageError(f"parameter '{parameter.name}' is missing"), given
    return None, given


def _type_error(parameters: List[_Parameter], given: dict) -> Optional[Exception]:
    """UsageError for the first argument whose type the parameter does not take (else None)."""
    from . import UsageError
    for parameter in parameters:
        if parameter.name in given and _fits(given[parameter.name], parameter.annotation) is False:
            return UsageError(f"parameter '{parameter.name}': must be {_describe(parameter.annotation)} "
                              f"(got {_shown(given[parameter.name])})")
    # Every type fits: a whole number beyond what the C++ parameter holds.
    for parameter in parameters:
        value = given.get(parameter.name)
        if _split_generic(parameter.annotation)[0] in ("int", "Optional") and isinstance(value, int) and \
                not isinstance(value, bool) and not -2**31 <= value < 2**31:
            return UsageError(f"parameter '{parameter.name}': must be a whole number of at most 32 bits "
                              f"(got {value})")
    return None


def _named_error(error: TypeError, args: tuple, kwargs: dict) -> Optional[Exception]:
    """The UsageError naming the parameter pybind11 refused, or None to keep its TypeError."""
    lines = str(error).splitlines()
    if not lines or not _INCOMPATIBLE.match(lines[0]):
        return None
    signatures = [match.group("parameters") for match in map(_SIGNATURE.match, lines[1:]) if match]
    # With overloads, the first whose parameters the arguments match (by number and by name) is
    # the one meant; when none does, what the first one misses is named.
    first_arity_error = None
    for signature in signatures:
        parameters = _parameters(signature)
        if parameters is None:
            return None
        arity_error, given = _arity_error(parameters, args, kwargs, "**kwargs" in signature)
        if arity_error is None:
            return _type_error(parameters, given)
        first_arity_error = first_arity_error or arity_error
    return first_arity_error


def _python_error(function: Callable, method: bool, args: tuple, kwargs: dict) -> Optional[Exception]:
    """For a function written in Python: the UsageError for arguments that match none of its
    parameters or leave one without a value, or None when they match (the TypeError came from
    within)."""
    try:
        signature = inspect.signature(function)
    except (TypeError, ValueError):
        return None
    listed = list(signature.parameters.values())[1 if method else 0:]  # a method's object left out
    variadic = (inspect.Parameter.VAR_POSITIONAL, inspect.Parameter.VAR_KEYWORD)
    parameters = [_Parameter(p.name, "", p.default is not inspect.Parameter.empty,
                             p.kind == inspect.Parameter.KEYWORD_ONLY) for p in listed if p.kind not in variadic]
    any_keyword = any(p.kind == inspect.Parameter.VAR_KEYWORD for p in listed)
    any_positional = any(p.kind == inspect.Parameter.VAR_POSITIONAL for p in listed)
    return _arity_error(parameters, args, kwargs, any_keyword, any_positional)[0]


def _wrapped(function: Callable, method: bool) -> Callable:
    python = inspect.isfunction(function)

    @functools.wraps(function)
    def call(*args, **kwargs):
        try:
            return function(*args, **kwargs)
        except TypeError as error:
            # A method's first argument is its object: the parameters are the arguments after it.
            arguments = args[1:] if method else args
            named = _python_error(function, method, arguments, kwargs) if python else \
                _named_error(error, arguments, kwargs)
            if named is None:
                raise
            raise named from None
    call.__ontime_wrapped__ = True
    return call


def _not_made_by_callers(cls: type) -> Callable:
    def refuse(self, *args, **kwargs):
        from . import UsageError
        raise UsageError(f"ontime.{cls.__name__} objects are not made by calling the class: OnTime's functions "
                         f"and methods return them")
    refuse.__ontime_wrapped__ = True
    return refuse


def _wrap_class(cls: type) -> None:
    """Wraps the constructor and the public methods of a class of the extension or of the package."""
    extension = type(cls).__name__ == "pybind11_type"
    for attribute, member in list(vars(cls).items()):
        if attribute.startswith("__") and attribute != "__init__":
            continue
        if getattr(member, "__ontime_wrapped__", False) or \
                getattr(getattr(member, "__func__", None), "__ontime_wrapped__", False):
            continue
        kind = type(member).__name__
        if attribute == "__init__" and extension and kind == "wrapper_descriptor":
            # A class of the extension without a constructor: pybind11 raises TypeError.
            setattr(cls, attribute, _not_made_by_callers(cls))
        elif kind == "instancemethod" or inspect.isfunction(member):
            setattr(cls, attribute, _wrapped(member, method=True))
        elif isinstance(member, staticmethod) and (type(member.__func__).__name__ == "builtin_function_or_method" or
                                                   inspect.isfunction(member.__func__)):
            setattr(cls, attribute, staticmethod(_wrapped(member.__func__, method=False)))


def name_wrong_arguments(module: Any) -> None:
    """Wraps the extension's functions and the methods and constructors of its classes in `module`,
    and the functions and classes written in Python in `module` itself. Wrapping twice wraps once."""
    for name, value in list(vars(module).items()):
        kind = type(value).__name__
        origin = str(getattr(value, "__module__", ""))
        if not origin.startswith("ontime") or getattr(value, "__ontime_wrapped__", False):
            continue  # not the extension's nor the package's, or wrapped already
        if kind == "builtin_function_or_method":
            setattr(module, name, _wrapped(value, method=False))
        elif inspect.isfunction(value) and origin == module.__name__ and not name.startswith("_"):
            setattr(module, name, _wrapped(value, method=False))
        elif kind == "pybind11_type" and not issubclass(value, BaseException):
            _wrap_class(value)
        elif isinstance(value, type) and origin == module.__name__ and not issubclass(value, BaseException):
            _wrap_class(value)
