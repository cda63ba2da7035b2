"""Reading YAML/JSON files into plain mappings, and pydantic validation with errors that
name the offending field. Every loader in :mod:`taut.io` (and the sweep file, and the
app's uploads) goes through these functions.

Two silent conversions are refused: a key given twice in one mapping (YAML and JSON
parsers keep the last value, refused by the parser here) and a boolean or a string where a
number is expected (pydantic's lax mode reads ``hold_height: true`` as 1): every file
model types its numbers :data:`Number` and :data:`Integer`, pydantic's strict types.

Files that could exhaust the machine are refused in one line before any work: a file
larger than :data:`MAX_FILE_BYTES` (YAML text longer than :data:`MAX_YAML_CHARS`: its
parser holds an object per value), and a YAML document whose aliases (``*name``) would
add more than :data:`MAX_YAML_VALUES` values to it (an "alias bomb": a few kB that
expand to billions of values). The expansion is counted on the parsed node graph (each
anchored node once), so a bomb is refused in milliseconds.

:func:`write_text_atomic` is how every command writes a file, and :func:`atomic_path`
how figures and animations are saved: a temporary file in the same folder, renamed over
the target, so an interrupted command never leaves half a file.
"""

from __future__ import annotations

import contextlib
import json
import os
import tempfile
import typing
from collections.abc import Iterator
from pathlib import Path
from typing import Annotated, Any, TypeVar

import yaml
from pydantic import BaseModel, ConfigDict, Strict, ValidationError

from ..errors import InvalidInputError, ScenarioError
from .._validate import as_path, require_instance

__all__ = ["read_text", "read_mapping", "parse_mapping", "validate_mapping", "write_json",
           "write_text_atomic", "atomic_path", "MAX_FILE_BYTES", "MAX_YAML_VALUES",
           "MAX_YAML_CHARS", "Number", "Integer", "StrictModel"]

M = TypeVar("M", bound=BaseModel)

#: A number in a file model: a float, or an integer read as a float; never a boolean or
#: a string (pydantic's lax ``float`` reads ``true`` as 1.0 and ``"2"`` as 2.0).
Number = Annotated[float, Strict()]
#: An integer in a file model; never a boolean, a float or a string.
Integer = Annotated[int, Strict()]


class StrictModel(BaseModel):
    """Base of every section of an input file: an unknown key and a NaN or infinite
    number are refused (the error names the dotted key, :func:`validate_mapping`)."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)


#: Error types of :data:`Number` and :data:`Integer` given a boolean: reported as
#: "must be a number, got a boolean", the wording of :mod:`taut._validate` for the API.
_NUMBER_ERRORS = frozenset({"float_type", "int_type"})

#: Largest input file read, bytes (scenarios, models, sweeps, trajectories: a few kB to a
#: few MB in practice).
MAX_FILE_BYTES = 32 * 2**20
#: Most values (scalars, lists, mappings) aliases may add to a YAML document (an alias
#: repeats its anchored value; a file without aliases is limited by its size alone).
MAX_YAML_VALUES = 100_000
#: Longest YAML text parsed, characters. A YAML parser holds a node object (~0.5 kB) per
#: value: 4.2 MB of number pairs took `taut fk` to 0.39 GB and 12 s, so a 32 MiB YAML file
#: would take ~3 GB; JSON (parsed compactly: 31 MiB measured at 0.72 GB) keeps
#: MAX_FILE_BYTES.
MAX_YAML_CHARS = 4 * 2**20

_UMASK = os.umask(0o022)          # read once at import (os.umask is not thread safe)
os.umask(_UMASK)


def read_text(path: str | Path) -> str:
    """The UTF-8 text of a file, without a leading byte-order mark (U+FEFF, which
    spreadsheet programs write and which would otherwise stick to the first cell or key).

    Raises
    ------
    ScenarioError
        Naming the path: missing, a directory or another non-regular file (a FIFO is
        refused without opening it, so it cannot block), larger than
        :data:`MAX_FILE_BYTES`, unreadable, or not UTF-8 (naming the line and byte).
    """
    path = as_path(path)
    p = Path(path)
    if not p.is_file():
        raise ScenarioError(str(path), _not_a_file(p))
    try:
        size = p.stat().st_size
        if size > MAX_FILE_BYTES:
            raise ScenarioError(str(path), f"file is {size / 2**20:.0f} MiB; at most "
                                           f"{MAX_FILE_BYTES // 2**20} MiB are read")
        data = p.read_bytes()
    except OSError as exc:
        raise ScenarioError(str(path), f"cannot read file ({exc.__class__.__name__})") from None
    try:
        return data.decode("utf-8").removeprefix("\ufeff")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        raise ScenarioError(f"{path}:{line}", f"not UTF-8 text (byte {exc.start + 1} of "
                                              "the file)") from None


def _not_a_file(p: Path) -> str:
    """Why ``p``, which is not a regular file, cannot be read."""
    if p.is_dir():
        return "is a directory, not a file"
    if p.exists():
        return "is not a regular file (a FIFO, socket or device); save it as a file"
    return "file not found"


_SafeBase: Any = getattr(yaml, "CSafeLoader", yaml.SafeLoader)


class _UniqueKeyLoader(_SafeBase):
    """PyYAML's safe loader (libyaml's parser when present), refusing a key that appears
    twice in one mapping."""


def _construct_unique_mapping(loader: yaml.SafeLoader, node: yaml.MappingNode,
                              deep: bool = False) -> dict[Any, Any]:
    seen: dict[Any, int] = {}
    for key_node, _ in node.value:
        key = loader.construct_object(key_node, deep=True)
        if key in seen:
            raise ScenarioError(str(key), f"duplicate key (lines {seen[key]} and "
                                          f"{key_node.start_mark.line + 1})")
        seen[key] = key_node.start_mark.line + 1
    return loader.construct_mapping(node, deep=deep)


_UniqueKeyLoader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG,
                                 _construct_unique_mapping)


def _unique_pairs(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for key, value in pairs:
        if key in out:
            raise ScenarioError(key, "duplicate key")
        out[key] = value
    return out


_HUGE = 2**62


def _alias_values(root: yaml.Node) -> int:
    """How many values aliases add: the size of the node graph with every alias expanded
    minus its distinct nodes (each node's size computed once, iteratively: linear in the
    number of distinct nodes)."""
    sizes: dict[int, int] = {}
    stack: list[tuple[yaml.Node, bool]] = [(root, False)]
    on_stack: set[int] = set()
    while stack:
        node, done = stack.pop()
        if id(node) in sizes:
            continue
        if isinstance(node, yaml.ScalarNode):
            sizes[id(node)] = 1
            continue
        children = ([c for pair in node.value for c in pair]
                    if isinstance(node, yaml.MappingNode) else list(node.value))
        if done:
            sizes[id(node)] = min(1 + sum(sizes.get(id(c), 1) for c in children), _HUGE)
            on_stack.discard(id(node))
            continue
        if id(node) in on_stack:          # a recursive alias: its own ancestor
            sizes[id(node)] = _HUGE
            continue
        on_stack.add(id(node))
        stack.append((node, True))
        stack.extend((c, False) for c in children if id(c) not in sizes)
    return sizes[id(root)] - len(sizes)


def _load_yaml(text: str, source: str) -> Any:
    if len(text) > MAX_YAML_CHARS:
        raise ScenarioError(source, f"YAML text of {len(text):,} characters; at most "
                                    f"{MAX_YAML_CHARS:,} are read as YAML (write larger "
                                    "data as JSON)")
    loader = _UniqueKeyLoader(text)
    try:
        node = loader.get_single_node()
        if node is None:
            return None
        if _alias_values(node) > MAX_YAML_VALUES:
            raise ScenarioError(source, f"YAML aliases add more than {MAX_YAML_VALUES:,} "
                                        "values (an alias bomb?)")
        return loader.construct_document(node)
    finally:
        loader.dispose()


def parse_mapping(text: str, source: str, *, suffix: str = ".yaml") -> dict[str, Any]:
    """Parse file text whose top level is a mapping, as :func:`read_mapping` does.

    Parameters
    ----------
    text : str
        The file's text (at most :data:`MAX_FILE_BYTES` bytes of UTF-8).
    source : str
        The name errors give as their field (a path or an upload's name).
    suffix : str
        ``".json"`` parses JSON; anything else YAML (JSON is YAML too).

    Raises
    ------
    ScenarioError
        Too large, a syntax error, an alias bomb, a key given twice, text that is not
        valid Unicode, or a top level that is not a mapping.

    Examples
    --------
    >>> parse_mapping("a: 1", "x.yaml")
    {'a': 1}
    >>> parse_mapping("a: &x [1, 2]\\nb: *x", "x.yaml")
    {'a': [1, 2], 'b': [1, 2]}
    """
    require_instance(text, str, "text")
    require_instance(source, str, "source")
    require_instance(suffix, str, "suffix")
    try:
        size = len(text.encode("utf-8"))
    except UnicodeEncodeError:
        raise ScenarioError(source, "text is not valid Unicode (a lone surrogate)") from None
    if size > MAX_FILE_BYTES:
        raise ScenarioError(source, f"file is {size / 2**20:.0f} MiB; at most "
                                    f"{MAX_FILE_BYTES // 2**20} MiB are read")
    path = source
    try:
        if suffix.lower() == ".json":
            data = json.loads(text, object_pairs_hook=_unique_pairs)
        else:
            data = _load_yaml(text, source)
    except json.JSONDecodeError as exc:
        raise ScenarioError(str(path), f"invalid JSON at line {exc.lineno}: {exc.msg}") from None
    except RecursionError:
        raise ScenarioError(str(path), "nested too deeply") from None
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" at line {mark.line + 1}" if mark is not None else ""
        raise ScenarioError(str(path), f"invalid YAML{where}") from None
    if not isinstance(data, dict):
        raise ScenarioError(str(path), "top level must be a mapping of keys to values")
    return data


def read_mapping(path: str | Path) -> dict[str, Any]:
    """Parse a ``.yaml``/``.yml``/``.json`` file whose top level is a mapping.

    Raises
    ------
    ScenarioError
        Missing, unreadable or too large file, a syntax error, an alias bomb, a key given
        twice, or a top level that is not a mapping (see :func:`parse_mapping`).
    """
    path = as_path(path)
    p = Path(path)
    return parse_mapping(read_text(p), str(path), suffix=p.suffix)


def _location(loc: tuple[Any, ...]) -> str:
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            out += ("." if out else "") + str(part)
    return out or "(top level)"


#: Steps pydantic adds to an error's location to say which branch of a union failed.
_UNION_TAGS = frozenset({"float", "int", "str", "bool", "none"})


def _data_loc(data: Any, loc: tuple[Any, ...]) -> tuple[Any, ...]:
    """An error location without pydantic's union-branch steps (``list[float]``,
    ``float``, ...) that are not keys of the file."""
    out: list[Any] = []
    for part in loc:
        inside = isinstance(data, dict) and part in data
        if isinstance(part, str) and not inside and ("[" in part or part in _UNION_TAGS):
            continue
        out.append(part)
        data = data[part] if inside else (
            data[part] if isinstance(data, list) and isinstance(part, int)
            and -len(data) <= part < len(data) else None)
    return tuple(out)


def _first_error(data: Any, errors: list[Any]) -> tuple[Any, tuple[Any, ...]]:
    """The error to report and its location in the file: the first error, or, when the
    value there failed every branch of a union (``3`` or ``[3, 4]``), the branch error
    deepest inside it (``routing_length[1]`` rather than ``routing_length``: not a
    number)."""
    best, where = errors[0], _data_loc(data, errors[0]["loc"])
    for err in errors[1:]:
        loc = _data_loc(data, err["loc"])
        if loc[:len(where)] == where and len(loc) > len(where):
            best, where = err, loc
    return best, where


def _models_in(kind: Any) -> list[type[BaseModel]]:
    """The pydantic models a field annotation can hold (through Optional, Union, list,
    dict values and Annotated)."""
    if isinstance(kind, type) and issubclass(kind, BaseModel):
        return [kind]
    args = [a for a in typing.get_args(kind) if a is not type(None)]
    if typing.get_origin(kind) is dict:
        args = args[1:]
    return [m for a in args for m in _models_in(a)]


def _known_keys(model: type[BaseModel], loc: tuple[Any, ...]) -> list[str]:
    """The keys the (sub)model at a pydantic error location takes; empty when the location
    does not lead to one model (so an unknown key's message can list what is known)."""
    models = [model]
    for part in loc:
        if not isinstance(part, str):
            continue                             # a list index: the same item model
        found = [m for mod in models if part in mod.model_fields
                 for m in _models_in(mod.model_fields[part].annotation)]
        if not found:
            return []
        models = found
    return list(models[0].model_fields) if len(models) == 1 else []


def validate_mapping(model: type[M], data: dict[str, Any]) -> M:
    """Validate ``data`` against a pydantic model; the first error becomes a
    :class:`ScenarioError` whose field is the dotted path (``sheet[2]``, ``cables[0].max``).

    A boolean where the model expects a number is refused by the model's own types
    (:data:`Number`, :data:`Integer`): one validation pass, no second walk over the data.
    """
    if not (isinstance(model, type) and issubclass(model, BaseModel)):
        raise ScenarioError("model", "must be a pydantic model class")
    require_instance(data, dict, "data")
    try:
        validated = model.model_validate(data)
    except ValidationError as exc:
        err, where = _first_error(data, exc.errors())
        loc = _location(where)
        msg = err["msg"]
        if err["type"] in _NUMBER_ERRORS and isinstance(err.get("input"), bool):
            msg = "must be a number, got a boolean"
        elif err["type"] == "extra_forbidden":
            keys = _known_keys(model, err["loc"][:-1])
            msg = f"unknown key; expected one of {', '.join(keys)}" if keys else "unknown key"
        elif err["type"] == "missing":
            msg = "required key is missing"
        raise ScenarioError(loc, msg[0].lower() + msg[1:]) from None
    return validated


def write_json(obj: Any, path: str | Path) -> None:
    """Write ``obj`` as indented, valid JSON (non-finite numbers become ``null``)."""
    path = as_path(path)
    from .serialize import to_json

    try:
        text = to_json(obj)
    except (TypeError, ValueError, RecursionError) as exc:
        raise InvalidInputError("obj", f"is not plain JSON data ({exc})") from None
    write_text_atomic(path, text + "\n")


def write_text_atomic(path: str | Path, text: str | bytes) -> None:
    """Write a file all at once (:func:`atomic_path`), so a reader sees the old file or
    the new one, never half of one, and an interrupt leaves no partial file.

    Raises
    ------
    InvalidInputError
        ``path``: the folder cannot be written; ``text`` neither ``str`` nor ``bytes``.
    """
    require_instance(text, (str, bytes), "text")
    data = text.encode("utf-8") if isinstance(text, str) else text
    with atomic_path(path) as tmp:
        tmp.write_bytes(data)


@contextlib.contextmanager
def atomic_path(path: str | Path) -> Iterator[Path]:
    """A temporary file next to ``path`` to write, renamed over ``path`` when the block
    ends without an error (:func:`os.replace` is atomic on POSIX and Windows) and removed
    when it fails or is interrupted. Its name ends like ``path`` (``.png``, ``.gif``), so
    writers that choose the format by the suffix (matplotlib) write the right one. A new
    file gets the usual permissions (0666 less the umask), a replaced one keeps its own.

    Raises
    ------
    InvalidInputError
        ``path``: the folder cannot be written.

    Examples
    --------
    >>> import tempfile
    >>> target = Path(tempfile.mkdtemp()) / "out.txt"
    >>> with atomic_path(target) as tmp:
    ...     _ = tmp.write_text("done")
    ...     target.exists()
    False
    >>> target.read_text(), sorted(p.name for p in target.parent.iterdir())
    ('done', ['out.txt'])
    """
    path = Path(as_path(path))
    try:
        fd, name = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp" + path.suffix,
                                    dir=path.parent if str(path.parent) else ".")
    except OSError as exc:
        raise InvalidInputError(str(path), f"cannot write ({exc.strerror or exc})") from None
    os.close(fd)
    tmp = Path(name)
    try:
        yield tmp
        if path.exists():
            try:
                os.chmod(tmp, path.stat().st_mode & 0o7777)
            except OSError:
                pass
        else:
            os.chmod(tmp, 0o666 & ~_UMASK)
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
