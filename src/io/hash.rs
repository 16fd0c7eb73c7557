//! Hash maps with a fixed, fast hasher (foldhash), so that no run depends
//! on a random seed.

/// A `HashMap` with foldhash's fixed state.
pub type HashMap<K, V> = std::collections::HashMap<K, V, foldhash::fast::FixedState>;
