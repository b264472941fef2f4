//! Fallible allocation of image-sized buffers. `Vec::with_capacity`, `vec![0; n]` and
//! `collect` abort the process when the allocator refuses (under `ulimit -v`, on a full
//! machine): SIGABRT, no message, staging folders left behind. Buffers whose size comes from
//! an image go through here instead, so running out of memory is an [`Error::OutOfMemory`]
//! naming the buffer and its size, and the run's error path cleans up as for any other error.

use crate::error::{Error, Result};

/// An empty vector with room for `len` elements, or an error naming `what` and the bytes.
pub fn try_with_capacity<T>(len: usize, what: &str) -> Result<Vec<T>> {
    let mut v = Vec::new();
    v.try_reserve_exact(len).map_err(|_| out_of_memory::<T>(len, what))?;
    Ok(v)
}

/// `len` copies of `value` (`vec![value; len]`, fallibly).
pub fn try_filled<T: Clone>(value: T, len: usize, what: &str) -> Result<Vec<T>> {
    let mut v = try_with_capacity(len, what)?;
    v.resize(len, value);
    Ok(v)
}

/// `bytes` reinterpreted as `T`s in a new vector (`bytemuck::pod_collect_to_vec`, fallibly).
pub fn try_pod_collect<T: bytemuck::Pod>(bytes: &[u8], what: &str) -> Result<Vec<T>> {
    let len = bytes.len().div_ceil(std::mem::size_of::<T>().max(1));
    let mut v: Vec<T> = try_filled(T::zeroed(), len, what)?;
    bytemuck::cast_slice_mut::<T, u8>(&mut v)[..bytes.len()].copy_from_slice(bytes);
    Ok(v)
}

/// A copy of `items` (`to_vec`, fallibly).
pub fn try_copy<T: Clone>(items: &[T], what: &str) -> Result<Vec<T>> {
    let mut v = try_with_capacity(items.len(), what)?;
    v.extend_from_slice(items);
    Ok(v)
}

fn out_of_memory<T>(len: usize, what: &str) -> Error {
    Error::OutOfMemory {
        what: what.to_string(),
        bytes: len.saturating_mul(std::mem::size_of::<T>()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_refused_allocation_is_an_error_naming_the_buffer_and_its_size() {
        // More than any address space holds: the allocator refuses, the process goes on.
        let len = usize::MAX / 8;
        let e = try_with_capacity::<u32>(len, "depth readback").unwrap_err().to_string();
        assert!(
            e.contains("depth readback") && e.contains(&(len * 4).to_string()),
            "{e}"
        );
        assert!(try_filled(0u8, 1 << 62, "colour").is_err());
        let v: Vec<f32> = try_pod_collect(bytemuck::cast_slice(&[1.5f32, 2.0]), "d").unwrap();
        assert_eq!(v, [1.5, 2.0]);
        assert_eq!(try_copy(&[1u8, 2, 3], "c").unwrap(), [1, 2, 3]);
    }
}
