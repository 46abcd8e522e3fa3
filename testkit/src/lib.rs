//! Test support for the colcos crates, a dev-dependency only: named scenarios built in code
//! ([`scenarios`]), fitted colour sensors ([`sensors`]), the per-pixel reference screen renderer
//! ([`screen`]), a counting global allocator ([`alloc`]), the digital twin on loopback ([`twin`]),
//! the swarm benchmark's scenario ([`swarm`]) and a rayon pool of a set size ([`threads`]). Tests of
//! scenario parsing keep their TOML text (with the help of [`parsing`]); everything else builds its
//! scenario here or with `ScenarioBuilder`.
pub mod alloc;
pub mod parsing;
pub mod scenarios;
pub mod screen;
pub mod sensors;
pub mod swarm;
pub mod threads;
pub mod twin;
