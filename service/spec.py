"""The OpenAPI description as generated clients read it: request defaults stated in words.

A request field the service defaults is optional. Most generators read it so, but
openapi-typescript (its default ``defaultNonNullable``) makes every property with a ``default``
required, so a request that leaves one out (``ik.blend_length``, ``placement.spin``) does not
compile under ``tsc --strict``. The components a request body reaches therefore carry no
``default`` keyword: each field's description says the default instead ("Default: 0.002."), and
the service applies it as before.
"""

from __future__ import annotations

import json
from typing import Any


def _refs(value: Any) -> set[str]:
    """The component names ``value`` refers to directly (``#/components/schemas/<name>``)."""
    if isinstance(value, dict):
        own = {value["$ref"].rsplit("/", 1)[-1]} if "$ref" in value else set()
        return own.union(*(_refs(item) for item in value.values()))
    if isinstance(value, list):
        return set().union(*(_refs(item) for item in value))
    return set()


def request_components(spec: dict[str, Any]) -> set[str]:
    """Every component a request body reaches, directly or through other components."""
    schemas = spec["components"]["schemas"]
    todo = {
        name
        for path in spec["paths"].values()
        for operation in path.values()
        for name in _refs(operation.get("requestBody", {}))
    }
    seen: set[str] = set()
    while todo:
        name = todo.pop()
        seen.add(name)
        todo |= _refs(schemas[name]) - seen
    return seen


def defaults_in_words(spec: dict[str, Any]) -> dict[str, Any]:
    """``spec`` with each request property's ``default`` moved into its description."""
    schemas = spec["components"]["schemas"]
    for name in request_components(spec):
        for field in schemas[name].get("properties", {}).values():
            if "default" not in field:
                continue
            default = field.pop("default")
            description = field.get("description", "")
            if "default" not in description.lower():
                field["description"] = f"{description} Default: {json.dumps(default)}.".strip()
    return spec
