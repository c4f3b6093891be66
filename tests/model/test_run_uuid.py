"""One namespace and one function mint every run id from a key (model.runs.run_uuid): a bag's id
is what it has been since the first release, and no other kind of key can give a bag's id."""

from __future__ import annotations

import hashlib
import uuid

from exsce_dsl.model.runs import RUN_NAMESPACE, run_uuid

FIRST_RELEASE = uuid.UUID("5b8f9a52-3f0c-4a8e-8f0e-2d6c1b7e4a90")
"""Written out by hand: stored runs' ids depend on it."""

DIGEST = hashlib.sha256(b"a bag").hexdigest()


def test_a_bag_s_run_id_is_uuid5_of_its_sha256_in_the_first_release_namespace() -> None:
    assert RUN_NAMESPACE == FIRST_RELEASE
    assert run_uuid(DIGEST) == str(uuid.uuid5(FIRST_RELEASE, DIGEST))


def test_a_bag_s_run_under_another_scenario_adds_the_scenario_s_iri() -> None:
    iri = "https://www.sesame-project.org/scenarios/scenario_c"
    assert run_uuid(DIGEST, iri) == str(uuid.uuid5(FIRST_RELEASE, f"{DIGEST} {iri}"))
    assert run_uuid(DIGEST, iri) != run_uuid(DIGEST)


def test_a_simulated_run_s_id_says_its_kind() -> None:
    simulated = run_uuid("simulated", "scenario_c/0/1/")
    assert simulated == run_uuid("simulated", "scenario_c/0/1/")
    assert simulated != run_uuid("scenario_c/0/1/")
    assert simulated != run_uuid("simulated", "scenario_c/0/2/")
