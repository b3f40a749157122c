"""The native engine's container cache is bounded (scfmu.engines.cache): least recently used entries go
first, entries in use are spared, a hit counts as a use, and a bad size bound is refused by name."""

from __future__ import annotations

import os

import pytest

from scfmu.engines import cache

MB = 1_000_000


def _entry(folder, name, size, age_s, now):
    p = folder / name
    p.parent.mkdir(parents=True, exist_ok=True)
    p.write_bytes(b"\0" * size)
    os.utime(p, (now - age_s, now - age_s))
    return p


def test_least_recently_used_go_first_until_the_rest_fit(tmp_path):
    now = 1_000_000.0
    a = _entry(tmp_path, "loop_a.fmu", 3 * MB, 5000, now)  # oldest
    b = _entry(tmp_path, "faces/x.me_1.fmu", 2 * MB, 4000, now)
    c = _entry(tmp_path, "loop_c.fmu", 4 * MB, 3000, now)
    d = _entry(tmp_path, "loop_d.fmu", 1 * MB, 10, now)  # in use
    other = _entry(tmp_path, "notes.txt", 50 * MB, 9000, now)  # not an entry
    # 10 MB of entries, bound 6 MB: a (3) and b (2) go, 5 MB remain
    assert cache.prune(tmp_path, budget=6 * MB, now=now) == [a, b]
    assert sorted(p.name for p in tmp_path.rglob("*") if p.is_file()) == ["loop_c.fmu", "loop_d.fmu", "notes.txt"]
    # bound 0: c goes, d is in use (used 10 s ago) and stays
    assert cache.prune(tmp_path, budget=0, now=now) == [c]
    assert d.exists() and other.exists()


def test_a_hit_counts_as_a_use(tmp_path):
    import time
    now = time.time()
    a = _entry(tmp_path, "loop_a.fmu", MB, 5000, now)
    b = _entry(tmp_path, "loop_b.fmu", MB, 4000, now)
    assert cache.used(a) == a
    assert cache.prune(tmp_path, budget=MB, now=time.time()) == [b]


@pytest.mark.parametrize("raw", ["0", "-5", "big", "nan", "inf"])
def test_a_bad_bound_is_refused_by_name(monkeypatch, raw):
    monkeypatch.setenv("SCFMU_CONTAINER_CACHE_MB", raw)
    with pytest.raises(ValueError, match=r"SCFMU_CONTAINER_CACHE_MB = .*megabytes > 0"):
        cache.budget_bytes()


def test_the_bound_in_bytes(monkeypatch):
    monkeypatch.setenv("SCFMU_CONTAINER_CACHE_MB", "2.5")
    assert cache.budget_bytes() == 2_500_000
    monkeypatch.delenv("SCFMU_CONTAINER_CACHE_MB")
    assert cache.budget_bytes() == 4096 * MB
