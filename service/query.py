"""Query parameters an operation does not take are refused, not ignored.

FastAPI reads the parameters an operation declares and drops the rest: ``POST
/v1/evaluate?detail=summary`` answered with every waypoint, as if the parameter had been read
(no POST operation takes one: its options are in the body). Every operation checks its query
string against the parameters it declares (a dependency of the app) and answers any other
with a 422 naming it, as an unknown field of a body is. The page, the docs and ``/metrics``
take any query string, as web pages and scrapers send them.

A parameter given twice is refused too (``?limit=1&limit=2`` took the last, without a word):
every parameter the API takes is one value.
"""

from __future__ import annotations

from fastapi import Request
from fastapi.exceptions import RequestValidationError
from fastapi.routing import APIRoute

API_PREFIX = "/v1/"
"""The operations checked: the API's."""


async def known_query_parameters(request: Request) -> None:
    """Refuse a query parameter the matched operation does not declare, or one given twice.

    Raises:
        RequestValidationError: at ``("query", name)`` for each one (cut to 100 characters).
    """
    if not request.query_params:
        return
    route = request.scope.get("route")
    if not isinstance(route, APIRoute) or not request.url.path.startswith(API_PREFIX):
        return  # the page, its docs and /metrics (a scraper's filters) are not operations
    declared = {field.alias for field in route.dependant.query_params}
    for sub in route.dependant.dependencies:  # parameters of the operation's dependencies
        declared.update(field.alias for field in sub.query_params)
    unknown = [name for name in request.query_params if name not in declared]
    repeated = [
        name
        for name in dict.fromkeys(request.query_params)
        if name in declared and len(request.query_params.getlist(name)) > 1
    ]
    if repeated and not unknown:
        raise RequestValidationError(
            [
                {
                    "loc": ("query", name),
                    "msg": f"{name!r} is given {len(request.query_params.getlist(name))} "
                    "times; give it once",
                    "type": "repeated",
                    "input": request.query_params.getlist(name)[:10],
                }
                for name in repeated
            ]
        )
    if unknown:
        taken = ", ".join(sorted(declared)) if declared else "none"
        hint = (
            "; a POST operation's options are fields of its body"
            if request.method == "POST"
            else ""
        )
        raise RequestValidationError(
            [
                {
                    "loc": ("query", name[:100]),
                    "msg": f"this operation takes no query parameter {name[:100]!r} (it takes: "
                    f"{taken}){hint}",
                    "type": "extra_forbidden",
                    "input": request.query_params[name][:100],
                }
                for name in unknown
            ]
        )
