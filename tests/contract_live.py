"""The committed OpenAPI spec against a live server, with every schemathesis check (issue 9).

The operations' tests are in two modules, ``tests/test_contract_evaluate_and_jobs.py`` and
``tests/test_contract_other_routes.py`` (split by :func:`evaluate_or_jobs`), each with its own
live server, so that the suite's two workers share them (in one module they were about 60 % of
the suite's test time on one worker, the other idle for minutes at the end); this module makes
both.

A uvicorn server is started with small work limits (so that a generated request cannot take
minutes); schemathesis generates requests from ``openapi/openapi.json`` in every phase
(examples, coverage, fuzzing; the picture operations' coverage phase negative cases only:
:data:`pictures`), seeded, a bounded number per operation, and runs all its checks:
no server error, documented statuses, content types and headers, responses that match their
schemas, schema-violating requests rejected (ST201) and schema-valid ones accepted (ST202). The
rules the spec states in words rather than JSON Schema are in ``tests/contract_hooks.py``:
positive cases are moved onto them, except those breaking a cross-field rule of
``contract_hooks.KEEP_OUT``, which run with every check but positive_data_acceptance; they must
stay under 2 % of the generated requests (MAX_KEPT_OUT).

A POST request the hooks made the same as one sent before (same mode) is not sent again:
:func:`sent_before`. The figures (cases and statuses per operation, the cases not sent again,
the cases normalised and kept out per rule, the share kept out) are written to
``tests/artifacts/contract-<part>.txt``, one file per module; ``.ci/run`` prints them.
"""

from __future__ import annotations

import json
import tomllib
from collections.abc import Callable, Iterator

import hypothesis
import requests
import schemathesis
from schemathesis.config import SchemathesisConfig
from schemathesis.specs.openapi.checks import positive_data_acceptance

from service.config import Settings
from tests import contract_hooks
from tests.cases import ROOT
from tests.live import start_server

LIMITS = {
    "max_map_cells": 2000,
    "max_map_poses": 200_000,
    "max_optimize_waypoints": 20,
    "max_path_waypoints": 500,
    # The contract, not the drawing, is tested (tests/service/test_map_picture.py draws more
    # panels): at 6 panels the map/png contract test took 101 s of the suite, alone 39 at 2.
    "max_png_panels": 2,
}
"""The live server's work limits: small, so that every generated request answers in seconds."""
ARTIFACTS = ROOT / "tests" / "artifacts"
MAX_KEPT_OUT = 0.02
"""The largest share of generated requests kept out of positive_data_acceptance."""
READ_TIMEOUT = 120
"""Seconds a request may take (a PNG of six panels on a loaded 2-core machine: over 10 s)."""


def live_server(part: str) -> Iterator[str]:
    """The URL of a live server with the contract limits; the figures written at the end.

    The body of each contract module's ``live_url`` fixture; ``part`` names its figures' file.
    """
    for counts in (
        contract_hooks.STATUSES,
        contract_hooks.KEPT_OUT,
        contract_hooks.NORMALISED,
        contract_hooks.REPEATED,
    ):
        counts.clear()  # this module's figures only, where both run in one process
    SENT.clear()
    env = {f"DTF_{name.upper()}": str(value) for name, value in LIMITS.items()}
    env |= {  # jobs: as small as the routes (the hooks size their requests alike), never refused
        "DTF_MAX_JOB_CELLS": str(LIMITS["max_map_cells"]),
        # A job weighs its scipy search against this limit as the route does against
        # DTF_MAX_SEARCH_POSES (the default here); its maps the hooks size to max_map_poses.
        "DTF_MAX_JOB_POSES": str(Settings.model_fields["max_search_poses"].default),
        "DTF_MAX_QUEUED_JOBS": "100000",
    }
    process, url = start_server({**env, "DTF_MAX_SOLVER_SECONDS": "2"})
    yield url
    process.terminate()
    process.wait(timeout=30)
    ARTIFACTS.mkdir(exist_ok=True)
    lines = [
        f"{n:6d}  {status}  {mode:8s}  {label}"
        for (label, mode, status), n in sorted(contract_hooks.STATUSES.items())
    ]
    total = sum(contract_hooks.STATUSES.values())
    kept = sum(contract_hooks.KEPT_OUT.values())
    share = kept / max(total, 1)
    lines += ["", "cases not sent again: the very request was sent and checked before"]
    repeated = sorted(contract_hooks.REPEATED.items())
    lines += [f"{n:6d}  {mode:8s}  {label}" for (label, mode), n in repeated]
    lines += ["", "positive cases moved onto a rule stated in words (per rule):"]
    lines += [f"{n:6d}  {rule}" for rule, n in sorted(contract_hooks.NORMALISED.items())]
    lines += ["", "positive cases kept out of positive_data_acceptance (rule, status):"]
    lines += [
        f"{n:6d}  {status}  {rule}: {contract_hooks.KEEP_OUT[rule]}"
        for (rule, status), n in sorted(contract_hooks.KEPT_OUT.items())
    ]
    lines += [
        f"kept out: {kept} of {total} generated requests = {100 * share:.2f} % "
        f"(limit {100 * MAX_KEPT_OUT:.0f} %)"
    ]
    (ARTIFACTS / f"contract-{part}.txt").write_text(
        f"{part}: schemathesis {schemathesis.__version__}, all checks, seed 1: {total} cases\n"
        + "\n".join(lines)
        + "\n"
    )
    assert total == 0 or share < MAX_KEPT_OUT, f"{kept} of {total} requests kept out"


SPEC = json.loads((ROOT / "openapi" / "openapi.json").read_text())
schema = schemathesis.openapi.from_dict(SPEC)
contract_hooks.register(schema, limits=LIMITS)
PICTURES = {"/v1/map/png", "/v1/evaluate/png"}
"""The picture operations, whose coverage phase makes negative cases only (:data:`pictures`)."""
pictures = schemathesis.openapi.from_dict(
    SPEC,
    config=SchemathesisConfig.from_dict(
        {
            **tomllib.loads((ROOT / "schemathesis.toml").read_text()),
            "phases": {"coverage": {"generation": {"mode": "negative"}}},
        }
    ),
)
"""The spec for the picture operations: they take the request models of ``POST /v1/map`` and
``POST /v1/evaluate`` (the same schema components), whose coverage phases make every positive
case; theirs drew a picture for each of their 423 and 415 (97 and 54 s of the suite's 668 s,
2026-12-06) for bodies the JSON operations answer. Their positive cases are the examples' and
the fuzzing's (and the pictures' own tests: tests/service/test_map_picture.py,
test_joint_use_picture.py). A schema of its own, with the repository's schemathesis.toml: an
``[[operations]]`` section there (or in a config given to one schema) made every contract test
run every operation (``include`` no longer filtered), 63,628 cases against 7,961."""
contract_hooks.register(pictures, limits=LIMITS)


SESSION = requests.Session()
SESSION.trust_env = False  # the live server is local: no proxy applies
SESSION.headers.clear()  # as schemathesis sends a case without one: the case's headers alone
"""The one HTTP session every contract case is sent on. schemathesis otherwise makes a session
for each case: a new connection each time, and requests reading every proxy variable of the
environment for each (4.8 of the 93 s of the jobs' test under a profiler, 2026-12-07)."""


SENT: set[tuple[str, ...]] = set()
"""The POST requests sent so far (:func:`sent_before`), with their generation mode and rule."""


def sent_before(case: schemathesis.Case, rule: str | None) -> bool:
    """Whether this very POST request was sent and checked before, in the same mode and rule.

    The hooks move many generated cases onto the same request (a cell's variations where the
    map and the optimisation drop the cell: 197 of the optimisation's 367 positive coverage
    cases were one request, each a full optimisation: 71 of the test's 80 s alone, 156 s in the
    suite, 2026-12-06). The service answers a request the same every time (the brief asks it;
    stop 59's audit checked it), so sending it again would check the same answer. The other
    methods (the job routes' reads and deletes) are sent every time: what they answer depends
    on what came before.
    """
    if case.method.upper() != "POST":
        return False
    mode = contract_hooks.mode(case)
    body = case.body
    text = body.hex() if isinstance(body, bytes) else json.dumps(body, sort_keys=True, default=str)
    key = (
        case.operation.label,
        case.formatted_path,
        json.dumps(case.query, sort_keys=True, default=str),
        json.dumps(case.headers, sort_keys=True, default=str),
        str(case.media_type),
        text,
        mode,
        str(rule),
    )
    if key in SENT:
        contract_hooks.REPEATED[(case.operation.label, mode)] += 1
        return True
    SENT.add(key)
    return False


def _contract_test(method: str, path: str) -> Callable[..., None]:
    """The contract test of one operation (one function each: contract_hooks.operations)."""

    @(pictures if path in PICTURES else schema).include(method=method, path=path).parametrize()
    @hypothesis.settings(
        max_examples=25,
        deadline=None,
        derandomize=True,
        database=None,
        suppress_health_check=list(hypothesis.HealthCheck),
    )
    def test(case: schemathesis.Case, live_url: str) -> None:
        rule = contract_hooks.kept_out(case)
        if sent_before(case, rule):
            return
        excluded = [] if rule is None else [positive_data_acceptance]
        response = case.call_and_validate(
            base_url=live_url, session=SESSION, excluded_checks=excluded, timeout=READ_TIMEOUT
        )
        if rule is not None:  # the service enforces the rule it states in words
            contract_hooks.KEPT_OUT[(rule, response.status_code)] += 1
            assert response.status_code == 422, (rule, response.text[:500])

    return test


def evaluate_or_jobs(name: str) -> bool:
    """Whether an operation (its test-name suffix) is ``POST /v1/evaluate`` or of ``/v1/jobs``.

    The split of the two contract modules: about 1,100 and 1,000 s of test time under load
    (2026-12-02; the evaluate route's JSON about 680 s, the jobs' 430 s, the evaluate route's
    PNG 650 s, the map's PNG 220 s, the optimisation 130 s).
    """
    return name == "post_v1_evaluate" or "_v1_jobs" in name


def contract_tests(names: Callable[[str], bool]) -> dict[str, Callable[..., None]]:
    """The contract tests of the operations whose test-name suffix ``names`` accepts, by name."""
    return {
        "test_contract_" + name: _contract_test(method, path)
        for method, path, name in contract_hooks.operations(schema)
        if names(name)
    }
