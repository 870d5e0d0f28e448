"""asp.batch's local Ray start-up, with a stand-in for Ray (no Ray needed): the workers get
their environment from the driver's, not from a runtime environment (which makes Ray start
another set of worker processes)."""

from __future__ import annotations

import os

from asp.batch import runner


class FakeRay:
    """Records ``init``'s keywords and the environment it saw."""

    def __init__(self) -> None:
        self.calls: list[tuple[dict, dict]] = []

    def init(self, **kw):
        self.calls.append((kw, {k: os.environ.get(k) for k in runner.WORKER_ENV}))


def test_local_ray_workers_inherit_the_worker_env_without_a_runtime_env(monkeypatch):
    monkeypatch.setenv("RAYON_NUM_THREADS", "7")
    monkeypatch.delenv("OMP_NUM_THREADS", raising=False)
    fake = FakeRay()
    runner._init_local(fake, 2)
    (kw, env), = fake.calls
    assert "runtime_env" not in kw and kw["num_cpus"] == 2
    assert env == runner.WORKER_ENV
    # the driver's own environment is as it was
    assert os.environ["RAYON_NUM_THREADS"] == "7" and "OMP_NUM_THREADS" not in os.environ
