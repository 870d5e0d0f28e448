//! glTF accessors read with explicit bounds checks (the `gltf` crate's iterators panic on some
//! malformed files): positions, indices, any component type, normalised or not, sparse or not.

use super::*;

pub(super) fn read_positions(accessor: &Accessor, buffers: &[Cow<[u8]>]) -> Res<Vec<DVec3>> {
    if accessor.dimensions() != Dimensions::Vec3 {
        return Err(format!("position accessor {} has unsupported type {:?} (expected vec3)", accessor.index(), accessor.dimensions())
            .to_lowercase());
    }
    let flat = read_accessor(accessor, buffers)?;
    Ok(flat.chunks_exact(3).map(|c| DVec3::new(c[0], c[1], c[2])).collect())
}

pub(super) fn read_indices(accessor: &Accessor, buffers: &[Cow<[u8]>], vertex_count: usize) -> Res<Vec<u32>> {
    let unsigned = matches!(accessor.data_type(), DataType::U8 | DataType::U16 | DataType::U32);
    if accessor.dimensions() != Dimensions::Scalar || !unsigned || accessor.normalized() {
        return Err(format!(
            "index accessor {} has unsupported type {:?} {:?} (expected scalar unsigned integers)",
            accessor.index(),
            accessor.dimensions(),
            accessor.data_type()
        )
        .to_lowercase());
    }
    read_accessor(accessor, buffers)?
        .into_iter()
        .map(|i| match i as usize {
            i if i < vertex_count => Ok(i as u32),
            i => Err(format!("index accessor {}: index {i} is out of range ({vertex_count} vertices)", accessor.index())),
        })
        .collect()
}

/// Every component of every element, as f64 (exact for all glTF component types), sparse
/// substitutions applied.
pub(super) fn read_accessor(accessor: &Accessor, buffers: &[Cow<[u8]>]) -> Res<Vec<f64>> {
    let layout =
        Layout { data_type: accessor.data_type(), components: accessor.dimensions().multiplicity(), normalized: accessor.normalized() };
    let count = accessor.count();
    let context = |reason: String| format!("accessor {}: {reason}", accessor.index());
    let mut values = match accessor.view() {
        Some(view) => {
            let bytes = view_bytes(&view, buffers).map_err(context)?;
            layout.read(bytes, accessor.offset(), view.stride(), count).map_err(context)?
        }
        None if count <= MAX_ZERO_FILLED => vec![0.0; count * layout.components],
        None => return Err(context(format!("count {count} without a buffer view is too large"))),
    };
    if let Some(sparse) = accessor.sparse() {
        apply_sparse(&mut values, &sparse, layout, buffers).map_err(context)?;
    }
    Ok(values)
}

/// Replaces the elements a sparse accessor lists.
fn apply_sparse(values: &mut [f64], sparse: &gltf::accessor::sparse::Sparse, layout: Layout, buffers: &[Cow<[u8]>]) -> Res<()> {
    use gltf::accessor::sparse::IndexType;
    let count = sparse.count();
    let (indices, substitutes) = (sparse.indices(), sparse.values());
    let index_layout = Layout {
        data_type: match indices.index_type() {
            IndexType::U8 => DataType::U8,
            IndexType::U16 => DataType::U16,
            IndexType::U32 => DataType::U32,
        },
        components: 1,
        normalized: false,
    };
    let targets = index_layout.read(view_bytes(&indices.view(), buffers)?, indices.offset(), None, count)?;
    let substitutes = layout.read(view_bytes(&substitutes.view(), buffers)?, substitutes.offset(), None, count)?;
    let n = layout.components;
    for (target, substitute) in targets.iter().zip(substitutes.chunks_exact(n)) {
        let start = *target as usize * n;
        let slot = values.get_mut(start..start + n).ok_or_else(|| format!("sparse index {target} is out of range"))?;
        slot.copy_from_slice(substitute);
    }
    Ok(())
}

/// The bytes of a buffer view, checked against its buffer.
fn view_bytes<'b>(view: &gltf::buffer::View, buffers: &'b [Cow<[u8]>]) -> Res<&'b [u8]> {
    let buffer = buffers.get(view.buffer().index()).ok_or_else(|| format!("buffer view {} has no buffer", view.index()))?;
    view.offset().checked_add(view.length()).and_then(|end| buffer.get(view.offset()..end)).ok_or_else(|| {
        format!(
            "buffer view {} (bytes {}..+{}) lies outside buffer {} ({} bytes)",
            view.index(),
            view.offset(),
            view.length(),
            view.buffer().index(),
            buffer.len()
        )
    })
}

/// How the elements of an accessor are stored.
#[derive(Clone, Copy)]
struct Layout {
    data_type: DataType,
    components: usize,
    normalized: bool,
}

impl Layout {
    /// Reads `count` elements starting at `offset`, `stride` bytes apart (tightly packed when
    /// None), after checking that they all lie inside `bytes`.
    fn read(self, bytes: &[u8], offset: usize, stride: Option<usize>, count: usize) -> Res<Vec<f64>> {
        let size = self.data_type.size();
        let element = size * self.components;
        let stride = stride.unwrap_or(element);
        if stride < element {
            return Err(format!("byte stride {stride} is smaller than an element ({element} bytes)"));
        }
        if count == 0 {
            return Ok(Vec::new());
        }
        let end = (count - 1).checked_mul(stride).and_then(|n| n.checked_add(element)).and_then(|n| n.checked_add(offset));
        if end.is_none_or(|end| end > bytes.len()) {
            return Err(format!("{count} elements at offset {offset} read past the end of the buffer view ({} bytes)", bytes.len()));
        }
        let mut values = Vec::with_capacity(count * self.components);
        for i in 0..count {
            let start = offset + i * stride;
            let element = &bytes[start..start + element];
            values.extend(element.chunks_exact(size).map(|c| self.component(c)));
        }
        Ok(values)
    }

    /// One component; normalized integers map to [0, 1] or [-1, 1] (glTF spec, section 3.11).
    fn component(self, b: &[u8]) -> f64 {
        let (value, max) = match self.data_type {
            DataType::I8 => (f64::from(b[0] as i8), 127.0),
            DataType::U8 => (f64::from(b[0]), 255.0),
            DataType::I16 => (f64::from(i16::from_le_bytes([b[0], b[1]])), 32767.0),
            DataType::U16 => (f64::from(u16::from_le_bytes([b[0], b[1]])), 65535.0),
            DataType::U32 => (f64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])), 1.0),
            DataType::F32 => (f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])), 1.0),
        };
        if self.normalized && max > 1.0 {
            (value / max).max(-1.0)
        } else {
            value
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normalized_components() {
        let layout = Layout { data_type: DataType::I8, components: 1, normalized: true };
        assert_eq!(layout.read(&[127, 0x80, 0], 0, None, 3).unwrap(), vec![1.0, -1.0, 0.0]);
        let layout = Layout { data_type: DataType::U16, components: 1, normalized: false };
        assert!(layout.read(&[1, 0, 2], 0, None, 2).is_err());
    }
}
