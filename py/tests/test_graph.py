"""The chapter-3 graph of a state as numpy arrays (docs/learning.md)."""

from __future__ import annotations

import numpy as np
import pytest

import asp
from conftest import LACK, ROOT


@pytest.fixture(scope="module")
def lack():
    return asp.load(ROOT / LACK, up="z")


def test_full_graph_shapes_and_dtypes(lack):
    g = lack.graph()
    n = len(lack)
    assert g.nodes.dtype == np.int64 and g.nodes.tolist() == list(range(n))
    assert g.x.dtype == np.float32 and g.x.shape == (n, g.node_dim)
    assert g.edge_index.dtype == np.int64 and g.edge_index.shape == (2, g.num_edges)
    assert g.edge_attr.dtype == np.float32 and g.edge_attr.shape == (g.num_edges, g.edge_dim)
    # defaults: 8 radius bins x degrees 0..8 = 72 descriptor floats; node +2, edge 2*72+2
    assert (g.node_dim, g.edge_dim) == (74, 152)
    assert g.features == "asp-graph/2 radius_bins=8 degree=8 points=2048"
    assert g.num_edges > 0 and g.num_edges % 2 == 0, "contacts give edges in both directions"
    assert np.isfinite(g.x).all() and np.isfinite(g.edge_attr).all()
    assert g.x.flags.writeable and g.x.flags.c_contiguous
    # edges ordered by (source, target), no loops, every edge also reversed
    pairs = list(zip(*g.edge_index.tolist()))
    assert pairs == sorted(pairs) and all(s != t for s, t in pairs)
    assert set(pairs) == {(t, s) for s, t in pairs}
    # the table stands on the ground: some part is on the base, none is fixed
    assert g.x[:, -2].sum() == 0 and g.x[:, -1].max() == 1


def test_state_graph_is_the_induced_subgraph(lack):
    full = lack.graph()
    present = [4, 0, 2, 3]
    g = lack.graph(present=present)
    keep = sorted(present)
    assert g.nodes.tolist() == keep
    np.testing.assert_array_equal(g.x, full.x[keep])
    position = {p: i for i, p in enumerate(keep)}
    expected = [k for k, (s, t) in enumerate(zip(*full.edge_index.tolist())) if s in position and t in position]
    assert g.num_edges == len(expected)
    np.testing.assert_array_equal(g.edge_attr, full.edge_attr[expected])
    for k, e in enumerate(expected):
        s, t = full.edge_index[:, e]
        assert (g.edge_index[0, k], g.edge_index[1, k]) == (position[s], position[t])


def test_empty_state_and_feature_parameters(lack):
    g = lack.graph(present=[])
    assert g.x.shape == (0, 74) and g.edge_index.shape == (2, 0) and g.edge_attr.shape == (0, 152)
    small = lack.graph(radius_bins=2, degree=3, points_per_part=256)
    assert small.node_dim == 2 * 4 + 2 and small.edge_dim == 2 * (2 * 4) + 6 + 2
    assert small.features == "asp-graph/2 radius_bins=2 degree=3 points=256"


def test_graph_is_deterministic_and_cached(lack):
    a = lack.graph()
    b = lack.graph()
    np.testing.assert_array_equal(a.x, b.x)
    np.testing.assert_array_equal(a.edge_attr, b.edge_attr)
    a.x[0, 0] = 123.0  # arrays are the caller's own
    assert lack.graph().x[0, 0] != 123.0


@pytest.mark.parametrize("kwargs, words", [
    ({"present": [99]}, "no part 99"),
    ({"present": [-1]}, "no part -1"),
    ({"degree": 100}, "degree"),
    ({"radius_bins": 0}, "radius"),
    ({"contact_distance": -1.0}, "contact_distance: must be a positive number"),
])
def test_bad_graph_settings_are_config_errors(lack, kwargs, words):
    with pytest.raises(asp.ConfigError, match=words):
        lack.graph(**kwargs)
