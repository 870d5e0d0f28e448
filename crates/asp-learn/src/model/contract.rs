//! The ONNX side of the model contract (docs/learning.md): the graph's inputs and output checked
//! by name, element type, rank and width before tract sees the file, and the initialisers the
//! Rust forward pass reads.

use super::INPUTS;
use tract_onnx::pb::{self, tensor_shape_proto::dimension, type_proto};

/// A boolean initialiser stored in the file (raw bytes or `int32_data`).
pub(super) fn bool_initializer(t: &pb::TensorProto) -> Option<(String, Vec<bool>)> {
    if t.data_type != BOOL {
        return None;
    }
    let len: usize = t.dims.iter().map(|&d| usize::try_from(d).ok()).product::<Option<usize>>()?;
    let values: Vec<bool> =
        if !t.raw_data.is_empty() { t.raw_data.iter().map(|&b| b != 0).collect() } else { t.int32_data.iter().map(|&b| b != 0).collect() };
    (values.len() == len).then(|| (t.name.clone(), values))
}

/// A float32 initialiser stored in the file (raw little-endian bytes or `float_data`).
pub(super) fn float_initializer(t: &pb::TensorProto) -> Option<(String, Vec<usize>, Vec<f32>)> {
    if t.data_type != FLOAT {
        return None;
    }
    let shape: Vec<usize> = t.dims.iter().map(|&d| usize::try_from(d).ok()).collect::<Option<_>>()?;
    let len: usize = shape.iter().product();
    let values: Vec<f32> = if !t.raw_data.is_empty() {
        t.raw_data.chunks_exact(4).map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect()
    } else {
        t.float_data.clone()
    };
    (values.len() == len).then(|| (t.name.clone(), shape, values))
}

/// Check the graph's inputs and outputs against the contract (names, types, ranks, widths).
pub(super) fn check_signature(graph: &pb::GraphProto, node_dim: usize, edge_dim: usize, output: &str) -> std::result::Result<(), String> {
    let initialisers: std::collections::HashSet<&str> = graph.initializer.iter().map(|t| t.name.as_str()).collect();
    let inputs: Vec<&pb::ValueInfoProto> = graph.input.iter().filter(|i| !initialisers.contains(i.name.as_str())).collect();
    let names: Vec<&str> = inputs.iter().map(|i| i.name.as_str()).collect();
    if names.len() != 3 || INPUTS.iter().any(|n| !names.contains(n)) {
        return Err(format!(
            "inputs are {}, expected 'x', 'edge_index', 'edge_attr'",
            names.iter().map(|n| format!("'{n}'")).collect::<Vec<_>>().join(", ")
        ));
    }
    let find = |name: &str| inputs.iter().find(|i| i.name == name).copied();
    let x = tensor_type("input", find("x"), "x")?;
    let ei = tensor_type("input", find("edge_index"), "edge_index")?;
    let ea = tensor_type("input", find("edge_attr"), "edge_attr")?;
    expect_type("input 'x'", x.0, FLOAT)?;
    expect_type("input 'edge_index'", ei.0, INT64)?;
    expect_type("input 'edge_attr'", ea.0, FLOAT)?;
    expect_rank("input 'x'", &x.1, 2, "[n, node_dim]")?;
    expect_rank("input 'edge_index'", &ei.1, 2, "[2, e]")?;
    expect_rank("input 'edge_attr'", &ea.1, 2, "[e, edge_dim]")?;
    if let Some(Dim::Fixed(d)) = x.1.as_ref().map(|s| s[1].clone()) {
        if d != node_dim as i64 {
            return Err(format!("input 'x' has {d} features, its asp.node_dim says {node_dim}"));
        }
    } else {
        return Err("input 'x' has no fixed feature count".into());
    }
    if let Some(Dim::Fixed(d)) = ea.1.as_ref().map(|s| s[1].clone()) {
        if d != edge_dim as i64 {
            return Err(format!("input 'edge_attr' has {d} features, its asp.edge_dim says {edge_dim}"));
        }
    } else {
        return Err("input 'edge_attr' has no fixed feature count".into());
    }
    if let Some(Dim::Fixed(d)) = ei.1.as_ref().map(|s| s[0].clone()) {
        if d != 2 {
            return Err(format!("input 'edge_index' has {d} rows, expected 2"));
        }
    }
    for (what, dims, axis, size) in
        [("input 'x'", &x.1, 0, "n"), ("input 'edge_index'", &ei.1, 1, "e"), ("input 'edge_attr'", &ea.1, 0, "e")]
    {
        if let Some(Dim::Fixed(d)) = dims.as_ref().map(|s| s[axis].clone()) {
            return Err(format!("{what} has a fixed size {d} on axis {axis}; {size} must be dynamic"));
        }
    }
    let outputs: Vec<&str> = graph.output.iter().map(|o| o.name.as_str()).collect();
    if outputs != [output] {
        return Err(format!(
            "outputs are {}, expected '{output}'",
            outputs.iter().map(|n| format!("'{n}'")).collect::<Vec<_>>().join(", ")
        ));
    }
    let out = tensor_type("output", graph.output.first(), output)?;
    expect_type(&format!("output '{output}'"), out.0, FLOAT)?;
    expect_rank(&format!("output '{output}'"), &out.1, 1, "[n]")?;
    Ok(())
}

pub(super) const FLOAT: i32 = 1;
/// ONNX `TensorProto.DataType.BOOL`.
pub(super) const BOOL: i32 = 9;
pub(super) const INT64: i32 = 7;

#[derive(Clone, Debug)]
pub(super) enum Dim {
    Fixed(i64),
    Dynamic,
}

pub(super) type TypeAndShape = (i32, Option<Vec<Dim>>);

pub(super) fn tensor_type(kind: &str, info: Option<&pb::ValueInfoProto>, name: &str) -> std::result::Result<TypeAndShape, String> {
    let info = info.ok_or_else(|| format!("has no {kind} '{name}'"))?;
    match info.r#type.as_ref().and_then(|t| t.value.as_ref()) {
        Some(type_proto::Value::TensorType(t)) => {
            let shape = t.shape.as_ref().map(|s| {
                s.dim
                    .iter()
                    .map(|d| match d.value {
                        Some(dimension::Value::DimValue(v)) => Dim::Fixed(v),
                        _ => Dim::Dynamic,
                    })
                    .collect()
            });
            Ok((t.elem_type, shape))
        }
        _ => Err(format!("{kind} '{name}' is not a tensor")),
    }
}

pub(super) fn type_name(code: i32) -> String {
    match code {
        1 => "float32".into(),
        2 => "uint8".into(),
        3 => "int8".into(),
        6 => "int32".into(),
        7 => "int64".into(),
        9 => "bool".into(),
        10 => "float16".into(),
        11 => "float64".into(),
        other => format!("element type {other}"),
    }
}

pub(super) fn expect_type(what: &str, got: i32, want: i32) -> std::result::Result<(), String> {
    if got == want {
        Ok(())
    } else {
        Err(format!("{what} is {}, expected {}", type_name(got), type_name(want)))
    }
}

pub(super) fn expect_rank(what: &str, shape: &Option<Vec<Dim>>, rank: usize, layout: &str) -> std::result::Result<(), String> {
    match shape {
        Some(s) if s.len() == rank => Ok(()),
        Some(s) => Err(format!("{what} has rank {}, expected {rank} ({layout})", s.len())),
        None => Err(format!("{what} has no declared shape, expected {layout}")),
    }
}
