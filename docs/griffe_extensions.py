"""griffe extensions for the API reference (mkdocs.yml names them in mkdocstrings' options).

- :class:`RuntimeDocstrings`: the compiled core's docstrings. griffe reads ``robodyn._core`` from
  its stub ``python/robodyn/_core.pyi``, which has the signatures and types but no docstrings; the
  docstrings are the Rust binding's ``///`` comments, which PyO3 makes the runtime ``__doc__`` of
  each class, method, property and function. The extension imports the module and gives every
  stub object without a docstring the one its runtime object has, so each page shows the stub's
  signature with the binding's text. A method the stub states only by its ``@overload``
  signatures becomes a member too (griffe keeps such signatures aside). A public class,
  function, method or property with no docstring in either place is a warning, which fails the
  strict build.
- :class:`SphinxRoles`: robodyn's docstrings are written for any reader (``help()``, an editor),
  with Sphinx's cross-reference roles (``:func:`load```) and ``::`` before an indented example.
  The site renders docstrings as Markdown: a role becomes a link to the object where it has a
  page (plain code where it has none), and ``::`` a colon.
"""

from __future__ import annotations

import importlib
import inspect
import re
from typing import Any

import griffe

#: The compiled module whose stub lacks the docstrings.
COMPILED = "robodyn._core"
#: A Sphinx cross-reference role: :func:`name`, :class:`~module.Name`, ...
ROLE = re.compile(r":(?:py:)?(?:func|class|meth|attr|data|mod|exc|obj|const):`~?([^`]+)`")
#: "text::" ending a line before an indented block (reStructuredText's literal block).
LITERAL_BLOCK = re.compile(r"(\S)::$", re.MULTILINE)


class RuntimeDocstrings(griffe.Extension):
    """Fills the stub's missing docstrings of :data:`COMPILED` from the imported module."""

    def on_package(self, *, pkg: griffe.Module, **kwargs: Any) -> None:
        package, name = COMPILED.split(".", 1)
        if pkg.path != package:
            return
        _fill(pkg[name], importlib.import_module(COMPILED))
        # a strict build fails on a public class, function, method or property left undocumented
        for obj in _objects(pkg[name]):
            public = not any(part.startswith("_") for part in obj.path.split(".")[2:])
            if public and obj.docstring is None and (obj.is_class or obj.is_function or obj.parent.is_class):
                griffe.logger.warning(f"{obj.path} has no docstring: the stub has none, nor the binding (a /// comment)")


class SphinxRoles(griffe.Extension):
    """Turns the docstrings' Sphinx roles into Markdown links and ``::`` into ``:``."""

    def on_package(self, *, pkg: griffe.Module, **kwargs: Any) -> None:
        for obj in _objects(pkg):
            if obj.docstring is not None:
                text = LITERAL_BLOCK.sub(r"\1:", obj.docstring.value)
                obj.docstring.value = ROLE.sub(lambda found: _link(obj, found.group(1)), text)


def _fill(stub: griffe.Object, runtime: object) -> None:
    """Gives ``stub`` and its members the runtime objects' docstrings where the stub has none."""
    _overloads_as_members(stub)
    if stub.docstring is None:
        text = _own_doc(stub, runtime)
        if text:
            stub.docstring = griffe.Docstring(inspect.cleandoc(text), parent=stub)
    for name, member in stub.members.items():
        if not member.is_alias and hasattr(runtime, name):
            # the attribute itself (a property, a method), not its value on the class
            _fill(member, inspect.getattr_static(runtime, name))


def _overloads_as_members(stub: griffe.Object) -> None:
    """A stub states an overloaded method by its ``@overload`` signatures alone, with no
    implementation, which griffe keeps aside (in ``overloads``) rather than as a member: each
    becomes a member here, with the last signature as its own and all of them as its overloads."""
    if not (stub.is_class or stub.is_module):
        return
    for name, signatures in list(stub.overloads.items()):
        if signatures and name not in stub.members:
            last = signatures[-1]
            function = griffe.Function(name, parameters=last.parameters, returns=last.returns,
                                       lineno=last.lineno, endlineno=last.endlineno)
            function.overloads = list(signatures)
            stub.set_member(name, function)


def _own_doc(stub: griffe.Object, runtime: object) -> str | None:
    """The runtime object's docstring, unless a class inherits it (``ValueError``'s says nothing
    about robodyn)."""
    text = getattr(runtime, "__doc__", None)
    if not text:
        return None
    if stub.is_class and isinstance(runtime, type) and any(text == base.__doc__ for base in runtime.__mro__[1:]):
        return None
    return text


def _objects(obj: griffe.Object) -> list[griffe.Object]:
    """``obj`` and every object defined in it (aliases left out), depth first."""
    found = [obj]
    for member in obj.members.values():
        if not member.is_alias:
            found += _objects(member)
    return found


def _link(obj: griffe.Object, name: str) -> str:
    """An optional cross-reference to ``name`` as seen from ``obj``: a link where the target has a
    page on the site, its name in code where it has none (mkdocs-autorefs drops it silently)."""
    head, _, rest = name.partition(".")
    scope = obj if obj.is_class or obj.is_module else obj.parent
    try:
        target = scope.resolve(head) if scope is not None else head
    except (griffe.NameResolutionError, ValueError):
        target = head
    path = f"{target}.{rest}" if rest else target
    return f'<autoref identifier="{path}" optional><code>{name}</code></autoref>'
