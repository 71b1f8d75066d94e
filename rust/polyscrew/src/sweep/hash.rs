//! A fast hash for the closed sweep's maps, keyed by mesh indices, edges and grid cubes.
//!
//! The standard library's SipHash resists keys chosen to collide, which these (made by the
//! contouring, not by a user) are not, and costs more per key. This is the
//! multiply-add hash of `rustc-hash` 2: a word at a time, rotated at the end so that the
//! table's low index bits see the product's high ones. No result depends on a map's order.

use std::collections::{HashMap, HashSet};
use std::hash::{BuildHasherDefault, Hasher};

/// The multiplier of `rustc-hash` 2 (64-bit).
const K: u64 = 0xf135_7aea_2e62_a9c5;

/// See the module documentation.
#[derive(Debug, Default, Clone, Copy)]
pub(super) struct FastHasher(u64);

impl FastHasher {
    #[inline]
    fn add(&mut self, word: u64) {
        self.0 = self.0.wrapping_add(word).wrapping_mul(K);
    }
}

impl Hasher for FastHasher {
    #[inline]
    fn finish(&self) -> u64 {
        self.0.rotate_left(26)
    }

    #[inline]
    fn write(&mut self, bytes: &[u8]) {
        for chunk in bytes.chunks(8) {
            let mut word = [0u8; 8];
            word[..chunk.len()].copy_from_slice(chunk);
            self.add(u64::from_le_bytes(word));
        }
    }

    #[inline]
    fn write_u8(&mut self, x: u8) {
        self.add(u64::from(x));
    }

    #[inline]
    fn write_u32(&mut self, x: u32) {
        self.add(u64::from(x));
    }

    #[inline]
    fn write_u64(&mut self, x: u64) {
        self.add(x);
    }

    #[inline]
    fn write_i64(&mut self, x: i64) {
        self.add(x as u64);
    }

    #[inline]
    fn write_usize(&mut self, x: usize) {
        self.add(x as u64);
    }
}

/// A `HashMap` with [`FastHasher`].
pub(super) type FastMap<K, V> = HashMap<K, V, BuildHasherDefault<FastHasher>>;

/// A `HashSet` with [`FastHasher`].
pub(super) type FastSet<K> = HashSet<K, BuildHasherDefault<FastHasher>>;

#[cfg(test)]
mod tests {
    use super::*;
    use std::hash::{BuildHasher, Hash};

    /// Distinct keys of each kind the sweep uses spread over a table's low bits: 4,096 keys of
    /// a grid's cubes, of a mesh's edges and of strided indices hit more than 58 % of a
    /// 4,096-slot table's slots (the low 12 bits of the hash, as hashbrown indexes), as a
    /// uniform hash would (about `1 - 1/e`, 63 %). Without the final rotation the strided
    /// indices would hit 64.
    #[test]
    fn grid_cubes_and_edges_spread_over_the_low_bits() {
        fn filled<T: Hash>(keys: impl Iterator<Item = T>) -> f64 {
            let build = BuildHasherDefault::<FastHasher>::default();
            let mut slots = vec![false; 4096];
            for k in keys {
                slots[(build.hash_one(k) & 4095) as usize] = true;
            }
            slots.iter().filter(|&&s| s).count() as f64 / 4096.0
        }
        let cubes = (0..16i64)
            .flat_map(|z| (0..16i64).flat_map(move |y| (0..16i64).map(move |x| [x, y, z])));
        let edges = (0..4096u32).map(|i| (i, i + 1 + i % 7));
        let indices = (0..4096u32).map(|i| i * 64);
        for (name, share) in [
            ("cubes", filled(cubes)),
            ("edges", filled(edges)),
            ("indices", filled(indices)),
        ] {
            assert!(share > 0.58, "{name}: {share}");
        }
    }
}
