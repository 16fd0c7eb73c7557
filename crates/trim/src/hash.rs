//! Hash maps and sets over vertex, face and edge indices.
//!
//! std's default hasher (SipHash, seeded per process) resists crafted keys,
//! which indices read from a mesh need not; it would take about a tenth of
//! `meshtrim clean`'s time. foldhash's fast hasher with a fixed seed is
//! several times cheaper on integer keys, and fixed, so iteration order is
//! the same in every run (no result depends on it anyway: outputs are
//! tested to be byte-identical across runs and thread counts).

/// A `HashMap` with foldhash's fixed-seed fast hasher.
pub type HashMap<K, V> = std::collections::HashMap<K, V, foldhash::fast::FixedState>;

/// A `HashSet` with foldhash's fixed-seed fast hasher.
pub type HashSet<K> = std::collections::HashSet<K, foldhash::fast::FixedState>;
