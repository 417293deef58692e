"""/docs reads as a manual: every schema has a description and an example, every field a
description, and every example is valid."""

from __future__ import annotations

import enum
import json
import typing
from typing import Any

import pytest
from pydantic import BaseModel
from typing_extensions import TypeAliasType

from service import schemas
from service.main import app
from service.spec import PAGED_MAP
from solver.core.family import KinematicsFamily
from solver.families import catalogue

MODELS = [
    model
    for name in schemas.__all__
    if isinstance(model := getattr(schemas, name), type)
    and issubclass(model, BaseModel)
    and model not in (schemas.RequestModel, schemas.ResponseModel)
]
COMPONENTS: dict[str, Any] = app.openapi()["components"]["schemas"]


@pytest.mark.parametrize("name", sorted(COMPONENTS))
def test_schema_is_documented(name: str) -> None:
    schema = COMPONENTS[name]
    assert schema.get("description"), name
    if "enum" in schema:  # an enum component: its values are its documentation
        assert schema["enum"] and schema["type"] == "string", name
        return
    assert schema.get("examples"), name
    undocumented = [
        key for key, field in schema["properties"].items() if "description" not in field
    ]
    assert not undocumented, f"{name}: {undocumented}"


@pytest.mark.parametrize("model", MODELS, ids=lambda model: model.__name__)
def test_examples_are_valid(model: type[BaseModel]) -> None:
    extra = model.model_config.get("json_schema_extra")
    assert isinstance(extra, dict)
    for example in extra["examples"]:
        model.model_validate(example)


def test_every_component_is_exported() -> None:
    enums = {
        name
        for name in schemas.__all__
        if isinstance(value := getattr(schemas, name), type) and issubclass(value, enum.Enum)
    }
    aliases = {  # named Literal types: one component each (SpinMode, JobStatus, ...)
        name for name in schemas.__all__ if isinstance(getattr(schemas, name), TypeAliasType)
    }
    derived = {PAGED_MAP}  # written by service.spec from MapResponse's component, no model
    assert set(COMPONENTS) == {model.__name__ for model in MODELS} | enums | aliases | derived


def test_failure_reasons_are_one_enum() -> None:
    """Issue 9: evaluate and map answers share one FailureReason component."""
    assert COMPONENTS["FailureReason"]["enum"] == [
        "unreachable",
        "joint_limits",
        "singular",
        "discontinuous",
        "collision",
    ]
    text = json.dumps(COMPONENTS)
    assert text.count('"discontinuous"') == 1


def _subclasses(cls: type) -> set[type]:
    return {sub for direct in cls.__subclasses__() for sub in {direct, *_subclasses(direct)}}


def test_the_answers_family_names_every_family_of_the_solver() -> None:
    """ik.family is a closed list in the contract: a family the solver adds answered 500 on
    /v1/evaluate until the schema named it (the seams audit). This holds the two together."""
    catalogue()  # every family module imported
    names = {getattr(c, "name", None) for c in _subclasses(KinematicsFamily)} - {None}
    assert names == set(typing.get_args(schemas.IkInfo.model_fields["family"].annotation))
