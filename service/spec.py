"""The OpenAPI description as generated clients read it: request defaults stated in words.

A request field the service defaults is optional. Most generators read it so, but
openapi-typescript (its default ``defaultNonNullable``) makes every property with a ``default``
required, so a request that leaves one out (``ik.blend_length``, ``placement.spin``) does not
compile under ``tsc --strict``. The components a request body reaches therefore carry no
``default`` keyword: each field's description says the default instead ("Default: 0.002."), and
the service applies it as before.
"""

from __future__ import annotations

import copy
import json
from typing import Any

PAGED_MAP = "MapResponseWithoutCells"
"""The component of a map job's answer whose cells are read in pages (``JobInfo.result``)."""


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


def with_paged_map(spec: dict[str, Any]) -> dict[str, Any]:
    """``spec`` with :data:`PAGED_MAP`: MapResponse without ``cells``, as it is, not written again.

    A map job over DTF_JOB_PAGE_CELLS answers its result without ``cells``
    (``result_cells.in_result`` false: they are read in pages); the spec said that result was a
    MapResponse, which requires them, so a generated client left it an untyped dict
    (openapi-python-client) or refused it (a strict validator). Derived from MapResponse's
    component, so the two never differ elsewhere.
    """
    schemas = spec["components"]["schemas"]
    paged = copy.deepcopy(schemas["MapResponse"])
    paged["properties"].pop("cells")
    paged["required"] = [name for name in paged.get("required", []) if name != "cells"]
    for example in paged.get("examples", []):
        example.pop("cells", None)
    paged["title"] = PAGED_MAP
    paged["description"] = (
        "A map job's answer whose cells are read in pages (JobInfo.result_cells.in_result false: "
        "more than DTF_JOB_PAGE_CELLS): MapResponse without cells."
    )
    schemas[PAGED_MAP] = paged
    return spec
