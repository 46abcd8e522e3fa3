#![allow(dead_code)]
use colcos_gpu::{AdapterPolicy, GpuContext};
use std::sync::{Arc, OnceLock};

/// The shared GPU context, or `None` (and a note on stderr) when no adapter exists. With
/// `COLCOS_REQUIRE_GPU=1` (CI, where lavapipe is installed) a missing adapter fails the test instead.
pub fn ctx() -> Option<Arc<GpuContext>> {
    static CTX: OnceLock<Option<Arc<GpuContext>>> = OnceLock::new();
    let c = CTX
        .get_or_init(|| match GpuContext::new(AdapterPolicy::Any) {
            Ok(c) => {
                eprintln!("GPU tests on {}", c.describe());
                Some(c)
            }
            Err(e) => {
                eprintln!("skipping GPU tests: {e}");
                None
            }
        })
        .clone();
    if c.is_none() && std::env::var("COLCOS_REQUIRE_GPU").is_ok_and(|v| v == "1") {
        panic!("COLCOS_REQUIRE_GPU=1 but no GPU adapter (install mesa-vulkan-drivers libvulkan1)");
    }
    c
}

/// Deterministic pseudo-random numbers in [0, 1).
pub struct Lcg(pub u64);
impl Lcg {
    pub fn next(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 40) as f32) / (1u64 << 24) as f32
    }
}

/// Largest |gpu - cpu| relative to the largest |cpu| value, and the number of bit-identical cells.
pub fn compare(gpu: &[f32], cpu: &[f32]) -> (f64, usize) {
    assert_eq!(gpu.len(), cpu.len());
    let scale = cpu
        .iter()
        .fold(0f64, |m, &v| m.max((v as f64).abs()))
        .max(1e-30);
    let mut worst = 0f64;
    let mut same = 0;
    for (&g, &c) in gpu.iter().zip(cpu) {
        assert!(g.is_finite(), "non-finite GPU value {g}");
        if g.to_bits() == c.to_bits() {
            same += 1;
        }
        worst = worst.max((g as f64 - c as f64).abs() / scale);
    }
    (worst, same)
}
