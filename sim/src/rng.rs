//! Seeded random streams. Every world, and every robot in it, draws from its own stream derived from
//! `(seed, world index, stream index)`, so results never depend on the number of threads.

use rand::SeedableRng;
pub use rand::rngs::SmallRng as SimRng;

/// SplitMix64 finaliser: spreads nearby seeds into unrelated 64-bit values.
pub fn mix64(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// The random stream `stream` of world `world` under `seed`.
pub fn stream(seed: u64, world: u64, stream: u64) -> SimRng {
    SimRng::seed_from_u64(mix64(mix64(mix64(seed) ^ world) ^ stream))
}

/// Every random stream of a world, and the id it derives from: the one table of stream ids, so that
/// no two users of a world's streams draw from the same one.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stream {
    /// Initial placement of the robots.
    Placement,
    /// The tracker model's noise and dropouts.
    Tracker,
    /// Robot `i`'s own stream: its sensor noise and its behaviour's choices.
    Robot(usize),
    /// The baseline policy of agent `i` of a batched environment.
    Baseline(usize),
    /// The noise of robot `i`'s telemetry readings in a digital twin.
    Telemetry(usize),
    /// The world's draws of its `[randomize]` ranges.
    Randomize,
}

impl Stream {
    /// First id of the baseline policies' streams: above every robot stream of any world.
    const BASELINE0: u64 = 1 << 40;
    /// First id of the twin's telemetry streams.
    const TELEMETRY0: u64 = 1 << 41;
    /// The domain randomisation's stream.
    const RANDOMIZE: u64 = 1 << 42;

    /// The stream's id under [`stream`].
    pub fn id(self) -> u64 {
        match self {
            Stream::Placement => 0,
            Stream::Tracker => 1,
            Stream::Robot(i) => 2 + i as u64,
            Stream::Baseline(i) => Self::BASELINE0 + i as u64,
            Stream::Telemetry(i) => Self::TELEMETRY0 + i as u64,
            Stream::Randomize => Self::RANDOMIZE,
        }
    }
}

/// The random stream `which` of world `world` under `seed`.
pub fn stream_of(seed: u64, world: u64, which: Stream) -> SimRng {
    stream(seed, world, which.id())
}

/// A standard normal sample: Marsaglia and Tsang's ziggurat with 128 layers in f32 (see [`Ziggurat`]).
/// One 64-bit draw, a table lookup and a multiply in 98.8 % of calls. rand_distr's `StandardNormal`
/// (the same method in f64 with generic plumbing) cost about 60 instructions a draw, and a robot's
/// colour sensors draw twelve per step.
#[inline]
pub fn normal(rng: &mut SimRng) -> f32 {
    normal_with(ziggurat(), rng)
}

/// [`normal`] with the tables fetched once by the caller ([`ziggurat`]): a robot's twelve draws check
/// the tables' one-time initialisation once.
#[inline(always)]
pub fn normal_with(z: &Ziggurat, rng: &mut SimRng) -> f32 {
    use rand::Rng;
    let bits = rng.next_u64();
    // Layer from the low 7 bits, value from the high 32: independent bits (Doornik 2005: taking both
    // from one 32-bit word correlates them).
    let layer = (bits & 127) as usize;
    let hz = (bits >> 32) as i32;
    if hz.unsigned_abs() < z.k[layer] {
        return hz as f32 * z.w[layer];
    }
    // The rare path on a copy: a caller's stream never has its address taken, so it can stay in
    // registers over a run of draws.
    let mut copy = rng.clone();
    let v = z.slow(&mut copy, hz, layer);
    *rng = copy;
    v
}

/// Tables of the 128-layer ziggurat for the standard normal (Marsaglia & Tsang 2000, "The ziggurat
/// method for generating random variables", J. Stat. Softw. 5(8); their `RNOR`/`nfix` with 64-bit
/// draws).
pub struct Ziggurat {
    /// Acceptance bounds on `|hz|` (a signed 32-bit draw) per layer.
    k: [u32; 128],
    /// `x_i / 2^31`: a draw `hz` maps to `hz * w[i]`.
    w: [f32; 128],
    /// The normal density (unnormalised) at each layer's edge.
    f: [f64; 128],
}

/// The tail starts at `R`: the rightmost layer edge.
const ZIG_R: f64 = 3.442619855899;
/// Area of each layer (and of the base strip with the tail).
const ZIG_V: f64 = 9.91256303526217e-3;

/// The ziggurat's tables, built once per process.
pub fn ziggurat() -> &'static Ziggurat {
    static TABLES: std::sync::OnceLock<Ziggurat> = std::sync::OnceLock::new();
    TABLES.get_or_init(Ziggurat::new)
}

impl Ziggurat {
    fn new() -> Self {
        let m1 = 2_147_483_648.0f64;
        let (mut k, mut w, mut f) = ([0u32; 128], [0f32; 128], [0f64; 128]);
        let mut dn = ZIG_R;
        let mut tn = dn;
        let q = ZIG_V / (-0.5 * dn * dn).exp();
        k[0] = (dn / q * m1) as u32;
        k[1] = 0;
        w[0] = (q / m1) as f32;
        w[127] = (dn / m1) as f32;
        f[0] = 1.0;
        f[127] = (-0.5 * dn * dn).exp();
        for i in (1..=126).rev() {
            dn = (-2.0 * (ZIG_V / dn + (-0.5 * dn * dn).exp()).ln()).sqrt();
            k[i + 1] = (dn / tn * m1) as u32;
            tn = dn;
            f[i] = (-0.5 * dn * dn).exp();
            w[i] = (dn / m1) as f32;
        }
        Ziggurat { k, w, f }
    }

    /// The rare cases: the tail beyond `R` (layer 0) and the wedges between a layer's rectangle and the
    /// density curve.
    #[cold]
    fn slow(&self, rng: &mut SimRng, mut hz: i32, mut layer: usize) -> f32 {
        use rand::Rng;
        // Uniform in (0, 1), never 0 (it goes into a logarithm).
        let uniform =
            |rng: &mut SimRng| ((rng.next_u64() >> 11) as f64 + 0.5) * (1.0 / (1u64 << 53) as f64);
        loop {
            let x = hz as f64 * self.w[layer] as f64;
            if layer == 0 {
                // Marsaglia's tail: x = -ln(u1) / R until -2 ln(u2) >= x^2.
                let (mut t, mut y);
                loop {
                    t = -uniform(rng).ln() / ZIG_R;
                    y = -uniform(rng).ln();
                    if y + y >= t * t {
                        break;
                    }
                }
                return (if hz > 0 { ZIG_R + t } else { -ZIG_R - t }) as f32;
            }
            if self.f[layer] + uniform(rng) * (self.f[layer - 1] - self.f[layer])
                < (-0.5 * x * x).exp()
            {
                return x as f32;
            }
            let bits = rng.next_u64();
            layer = (bits & 127) as usize;
            hz = (bits >> 32) as i32;
            if hz.unsigned_abs() < self.k[layer] {
                return hz as f32 * self.w[layer];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::RngExt;

    /// The ranges of the stream table do not overlap for any world a scenario can describe.
    #[test]
    fn stream_ids_do_not_collide() {
        assert!(Stream::Robot(1 << 30).id() < Stream::Baseline(0).id());
        assert!(Stream::Baseline(1 << 30).id() < Stream::Telemetry(0).id());
        assert!(Stream::Telemetry(1 << 30).id() < Stream::Randomize.id());
        assert_eq!(Stream::Placement.id(), 0);
        assert_eq!(Stream::Tracker.id(), 1);
        assert_eq!(Stream::Robot(0).id(), 2);
    }

    #[test]
    fn streams_differ_and_repeat() {
        let a: u64 = stream(1, 0, 0).random();
        let b: u64 = stream(1, 0, 1).random();
        let c: u64 = stream(1, 1, 0).random();
        assert_ne!(a, b);
        assert_ne!(a, c);
        assert_eq!(a, stream(1, 0, 0).random::<u64>());
    }

    #[test]
    fn normal_has_unit_variance() {
        let mut rng = stream(7, 0, 0);
        let n = 20_000;
        let xs: Vec<f32> = (0..n).map(|_| normal(&mut rng)).collect();
        let mean = xs.iter().sum::<f32>() / n as f32;
        let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f32>() / n as f32;
        assert!(mean.abs() < 0.03, "mean {mean}");
        assert!((var - 1.0).abs() < 0.05, "var {var}");
    }

    /// Standard normal CDF (Abramowitz & Stegun 26.2.17, error below 7.5e-8).
    fn phi(x: f64) -> f64 {
        let t = 1.0 / (1.0 + 0.2316419 * x.abs());
        let poly = t
            * (0.319381530
                + t * (-0.356563782 + t * (1.781477937 + t * (-1.821255978 + t * 1.330274429))));
        let tail = (-0.5 * x * x).exp() / (2.0 * std::f64::consts::PI).sqrt() * poly;
        if x >= 0.0 { 1.0 - tail } else { tail }
    }

    /// The ziggurat's samples follow the normal law: Kolmogorov-Smirnov distance over 400,000 draws
    /// (critical value at the 0.1 % level: 1.95 / sqrt(n) = 0.0031), and the tail beyond the last
    /// layer (|x| > 3.44, probability 5.76e-4) as often as it should be, both signs.
    #[test]
    fn ziggurat_follows_the_normal_law() {
        let mut rng = stream(11, 0, 0);
        let n = 400_000;
        let mut xs: Vec<f64> = (0..n).map(|_| normal(&mut rng) as f64).collect();
        xs.sort_by(f64::total_cmp);
        let d = xs
            .iter()
            .enumerate()
            .map(|(i, &x)| {
                let c = phi(x);
                (c - i as f64 / n as f64)
                    .abs()
                    .max(((i + 1) as f64 / n as f64 - c).abs())
            })
            .fold(0.0, f64::max);
        assert!(d < 1.95 / (n as f64).sqrt(), "KS distance {d}");
        let (lo, hi) = (
            xs.iter().filter(|&&x| x < -ZIG_R).count(),
            xs.iter().filter(|&&x| x > ZIG_R).count(),
        );
        let want = n as f64 * phi(-ZIG_R);
        for count in [lo, hi] {
            assert!(
                (count as f64 - want).abs() < 5.0 * want.sqrt(),
                "tail {count} vs {want}"
            );
        }
        assert!(
            xs[0] < -4.0 && xs[n - 1] > 4.0,
            "no deep tail: {} {}",
            xs[0],
            xs[n - 1]
        );
    }
}
