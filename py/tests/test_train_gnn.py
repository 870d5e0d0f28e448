"""Tests of the removability GNN (``asp.train.gnn``) and its ONNX export (``asp.train.export``)."""

from __future__ import annotations

import numpy as np
import pytest

from conftest import need

torch = need("torch", "asp.train needs PyTorch (pip install torch)")
onnx = need("onnx", "the ONNX export needs the onnx package")

from asp.train.export import ExportError, export_onnx, parity_check, random_graph, run_onnx  # noqa: E402
from asp.train.gnn import RemovabilityGNN  # noqa: E402

NODE_DIM, EDGE_DIM = 12, 7


def _model(seed: int = 0, **kw) -> RemovabilityGNN:
    torch.manual_seed(seed)
    model = RemovabilityGNN(NODE_DIM, EDGE_DIM, **kw).eval()
    rng = np.random.default_rng(seed)
    x, _, a = random_graph(50, 200, NODE_DIM, EDGE_DIM, rng)
    model.fit_normalisation(torch.from_numpy(x), torch.from_numpy(a))
    return model


def _graph(n: int, e: int, seed: int = 1):
    x, ei, ea = random_graph(n, e, NODE_DIM, EDGE_DIM, np.random.default_rng(seed))
    return torch.from_numpy(x), torch.from_numpy(ei), torch.from_numpy(ea)


def test_output_shape_and_range():
    model = _model()
    with torch.no_grad():
        for n, e in [(1, 0), (5, 0), (9, 30), (40, 160)]:
            y = model(*_graph(n, e))
            assert y.shape == (n,)
            assert torch.isfinite(y).all() and (y > 0).all() and (y < 1).all()


def test_permutation_equivariance():
    model = _model()
    x, ei, ea = _graph(17, 60)
    perm = torch.from_numpy(np.random.default_rng(3).permutation(17))
    inverse = torch.argsort(perm)  # node i of the original graph is node inverse[i] of the relabelled one
    edge_perm = torch.from_numpy(np.random.default_rng(4).permutation(ei.shape[1]))
    with torch.no_grad():
        y = model(x, ei, ea)
        y_perm = model(x[perm], inverse[ei][:, edge_perm], ea[edge_perm])
    torch.testing.assert_close(y_perm, y[perm], rtol=0, atol=1e-6)


def test_messages_flow_from_source_to_target():
    # one edge 0 -> 1: the target's output depends on the source's attributes, not the reverse
    model = _model()
    x, _, _ = _graph(2, 0)
    ei = torch.tensor([[0], [1]])
    ea = torch.from_numpy(np.random.default_rng(5).gamma(2.0, 0.5, (1, EDGE_DIM)).astype(np.float32))
    x2 = x.clone()
    x2[0, :3] += 5.0
    x3 = x.clone()
    x3[1, :3] += 5.0
    with torch.no_grad():
        y, y_source_changed = model(x, ei, ea), model(x2, ei, ea)
        y_target_changed = model(x3, ei, ea)
    assert abs(float(y_source_changed[1] - y[1])) > 1e-6  # the target hears its source
    assert abs(float(y_target_changed[0] - y[0])) < 1e-7  # the source hears nothing


def test_isolated_nodes_and_no_edges():
    model = _model()
    x, ei, ea = _graph(6, 0)
    with torch.no_grad():
        alone = model(x[:1], ei, ea)
        y = model(x, ei, ea)
    assert torch.isfinite(y).all()
    torch.testing.assert_close(y[:1], alone, rtol=0, atol=1e-7)  # no edges: nodes are independent


def test_dense_and_scatter_aggregations_agree():
    model = _model()
    x, ei, ea = _graph(31, 120)
    with torch.no_grad():
        a = model(x, ei, ea)
        model.set_aggregation("dense")
        b = model(x, ei, ea)
    torch.testing.assert_close(a, b, rtol=0, atol=1e-6)


def test_large_scores_stay_finite():
    model = _model()
    with torch.no_grad():
        model.encoder.temperature.fill_(1e4)  # a huge temperature: exp would overflow without the shift/clamp
        y = model(*_graph(20, 80))
    assert torch.isfinite(y).all()


def test_gradients_reach_every_parameter():
    model = _model().train()
    x, ei, ea = _graph(20, 80)
    model.logits(x, ei, ea).sum().backward()
    for name, p in model.named_parameters():
        assert p.grad is not None and torch.isfinite(p.grad).all(), name
        assert float(p.grad.abs().sum()) > 0, name


def test_normalisation_is_baked_in():
    model = _model()
    assert float(model.encoder.node_std[0]) != 1.0 and float(model.encoder.node_mean[0]) != 0.0
    assert set(dict(model.named_buffers())) >= {f"encoder.{b}" for b in ("node_mean", "node_std", "edge_mean", "edge_std")}


@pytest.mark.parametrize("aggregation", ["scatter", "dense"])
def test_export_matches_pytorch_on_unseen_sizes(tmp_path, aggregation):
    model = _model(seed=2)
    path = tmp_path / "m.onnx"
    diff = export_onnx(model, path, "test/1 a=1", aggregation=aggregation)
    assert diff is not None and diff <= 1e-5
    proto = onnx.load(str(path))
    assert proto.opset_import[0].version == 17
    assert [i.name for i in proto.graph.input] == ["x", "edge_index", "edge_attr"]
    assert [o.name for o in proto.graph.output] == ["removability"]
    dims = {i.name: [d.dim_param or d.dim_value for d in i.type.tensor_type.shape.dim] for i in proto.graph.input}
    assert dims == {"x": ["n", NODE_DIM], "edge_index": [2, "e"], "edge_attr": ["e", EDGE_DIM]}
    out_dims = [d.dim_param or d.dim_value for d in proto.graph.output[0].type.tensor_type.shape.dim]
    assert out_dims == ["n"]
    elem = {i.name: i.type.tensor_type.elem_type for i in proto.graph.input}
    assert elem == {"x": onnx.TensorProto.FLOAT, "edge_index": onnx.TensorProto.INT64, "edge_attr": onnx.TensorProto.FLOAT}
    meta = {p.key: p.value for p in proto.metadata_props}
    assert meta["asp.kind"] == "removability"
    assert meta["asp.features"] == "test/1 a=1"
    assert meta["asp.node_dim"] == str(NODE_DIM) and meta["asp.edge_dim"] == str(EDGE_DIM)
    ops = {n.op_type for n in proto.graph.node}
    assert ("ScatterND" in ops) == (aggregation == "scatter")
    # one more unseen size, with an isolated node
    x, ei, ea = _graph(77, 300, seed=9)
    ei = ei[:, ei[1] != 0]
    ea = ea[: ei.shape[1]]
    with torch.no_grad():
        expected = model(x, ei, ea).numpy()
    got = run_onnx(path, x.numpy(), ei.numpy(), ea.numpy())
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-5)


def test_parity_check_catches_a_different_model(tmp_path):
    path = tmp_path / "m.onnx"
    export_onnx(_model(seed=2), path, "test/1")
    with pytest.raises(ExportError, match="ONNX and PyTorch differ"):
        parity_check(_model(seed=3), path)


def test_parity_holds_with_small_descriptor_entries(tmp_path):
    # Descriptor entries of real parts are often tiny (high degrees, outer shells) and vary little,
    # so normalisation divides their log by a small std. PyTorch's log1p and ONNX's Log(1 + v)
    # (ONNX has no Log1p) differed there by ulp(1) / v relative, and the trained shipped model's
    # outputs by 1e-4; the model now computes log(1 + v) itself, so both run the same float ops.
    torch.manual_seed(5)
    model = RemovabilityGNN(NODE_DIM, EDGE_DIM).eval()
    rng = np.random.default_rng(5)
    x, ei, ea = random_graph(60, 240, NODE_DIM, EDGE_DIM, rng)
    x[:, :-2] = rng.uniform(1e-4, 1.2e-4, size=(60, NODE_DIM - 2)).astype(np.float32)
    ea[:, :-2] = rng.uniform(3e-5, 3.5e-5, size=(ea.shape[0], EDGE_DIM - 2)).astype(np.float32)
    model.fit_normalisation(torch.from_numpy(x), torch.from_numpy(ea))
    path = tmp_path / "small.onnx"
    export_onnx(model, path, "test/1 a=1", check=False)
    with torch.no_grad():
        expected = model(torch.from_numpy(x), torch.from_numpy(ei), torch.from_numpy(ea)).numpy()
        exact_log1p = torch.where(model.encoder.node_log_mask, torch.log1p(torch.from_numpy(x)), torch.from_numpy(x))
        ours = torch.where(model.encoder.node_log_mask, torch.log(1.0 + torch.from_numpy(x)), torch.from_numpy(x))
    # the inputs do exercise the difference between the two logs (with torch.log1p the outputs
    # differed by 5.8e-5)
    assert float((exact_log1p - ours).abs().max()) > 1e-9
    got = run_onnx(path, x, ei, ea)
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-5)


# -- the shared graph encoder ---------------------------------------------------------------------
def _q_model(seed: int = 0):
    from asp.train.q import QNetwork

    torch.manual_seed(seed)
    model = QNetwork(NODE_DIM, EDGE_DIM, width=16, layers=2).eval()
    rng = np.random.default_rng(seed)
    x, _, a = random_graph(50, 200, NODE_DIM, EDGE_DIM, rng)
    model.fit_normalisation(torch.from_numpy(x), torch.from_numpy(a))
    return model


def test_both_models_compose_the_shared_encoder():
    from asp.train.encoder import GraphEncoder
    from asp.train.q import MIN_STD

    gnn, q = _model(), _q_model()
    assert type(gnn.encoder) is GraphEncoder and type(q.encoder) is GraphEncoder
    # the Q network is not a removability network with its head switched off
    assert not isinstance(q, RemovabilityGNN) and not hasattr(q, "head") and not hasattr(q, "logits")
    assert {k.split(".")[0] for k in q.state_dict()} == {"encoder", "phi_q"}
    assert {k.split(".")[0] for k in gnn.state_dict()} == {"encoder", "head"}
    # the shape a model reports is its encoder's (export and the weight files read it)
    assert (q.node_dim, q.edge_dim, q.width, q.layers, q.aggregation) == (NODE_DIM, EDGE_DIM, 16, 2, "scatter")
    # Q inputs are only standardised (no log1p), with stds floored at MIN_STD
    assert not q.encoder.node_log_mask.any() and gnn.encoder.node_log_mask[: NODE_DIM - 2].all()
    assert float(q.encoder.node_std.min()) >= MIN_STD and float(q.encoder.edge_std.min()) >= MIN_STD


@pytest.mark.parametrize("make", [_model, _q_model], ids=["removability", "q"])
def test_state_dicts_from_before_the_encoder_split_still_load(make):
    # weights saved when the encoder's parameters sat on the model itself (``node_encoder.weight``,
    # ``node_mean``, ...; e.g. a ``q.onnx.pt`` of python -m asp.train q) load into the new layout
    trained = make(seed=3)
    flat = {k[len("encoder."):] if k.startswith("encoder.") else k: v for k, v in trained.state_dict().items()}
    assert "node_encoder.weight" in flat and "node_mean" in flat
    fresh = make(seed=4)
    g = _graph(15, 40)
    with torch.no_grad():
        assert not torch.equal(fresh(*g), trained(*g))
        fresh.load_state_dict(flat)
        torch.testing.assert_close(fresh(*g), trained(*g), rtol=0, atol=0)


@pytest.mark.parametrize("make, kind, output", [(_model, "removability", "removability"), (_q_model, "q", "q")])
def test_exported_graph_keeps_the_contract_names_and_shapes(tmp_path, make, kind, output):
    # docs/learning.md: inputs x [n, node_dim], edge_index int64 [2, e], edge_attr [e, edge_dim],
    # one output [n]; a Q model (no log1p) has no Log op, a removability model has
    model = make(seed=1)
    path = tmp_path / "m.onnx"
    export_onnx(model, path, "test/1 a=1", kind=kind, output_name=output, check=False)
    proto = onnx.load(str(path))

    def dims(value):
        return [d.dim_param or d.dim_value for d in value.type.tensor_type.shape.dim]

    inputs = {i.name: dims(i) for i in proto.graph.input}
    assert inputs == {"x": ["n", NODE_DIM], "edge_index": [2, "e"], "edge_attr": ["e", EDGE_DIM]}
    assert [(o.name, dims(o)) for o in proto.graph.output] == [(output, ["n"])]
    assert {p.key: p.value for p in proto.metadata_props}["asp.kind"] == kind
    assert ("Log" in {n.op_type for n in proto.graph.node}) == (kind == "removability")
