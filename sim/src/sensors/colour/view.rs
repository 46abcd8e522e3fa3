//! What a colour sensor looks at ([`ScreenView`]): the arguments every read passes down together,
//! and the screen's levels at the footprints' samples with printed obstacles drawn over them.
use super::FOOTPRINT_POINTS;
use crate::arena::Printed;
use crate::field::{FrozenSources, Pheromone};
use crate::screen::{FootprintLevels, FootprintSamples, ScreenSpec, footprint_levels};
use glam::Vec2;

/// The screen a colour sensor reads: the pheromones it draws, their Gaussian sources as they are
/// now (`frozen`, [`FrozenSources::new`]; a world refreshes one per step for all its sensors), the
/// panel, and the printed obstacles drawn over the pheromones (if any).
#[derive(Clone, Copy)]
pub struct ScreenView<'a> {
    pub pheromones: &'a [Pheromone],
    pub frozen: &'a FrozenSources,
    pub screen: &'a ScreenSpec,
    pub printed: Option<&'a Printed>,
}

impl ScreenView<'_> {
    /// The 8-bit levels at four footprints' samples ([`footprint_levels`]), printed obstacles
    /// drawn over them.
    #[inline(always)]
    pub(super) fn levels(&self, samples: &FootprintSamples) -> FootprintLevels {
        let levels = footprint_levels(self.pheromones, self.frozen, self.screen, samples);
        self.painted(samples, levels)
    }

    /// [`ScreenView::levels`] in AVX2 registers, for callers already compiled for AVX2.
    ///
    /// # Safety
    /// The CPU has AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    #[inline]
    pub(super) unsafe fn levels_avx2(&self, samples: &FootprintSamples) -> FootprintLevels {
        // SAFETY: the CPU has AVX2 (this function's contract).
        let levels = unsafe {
            crate::screen::footprint_levels_avx2(self.pheromones, self.frozen, self.screen, samples)
        };
        self.painted(samples, levels)
    }

    /// `levels` with the printed obstacles drawn over them, if the arena prints any.
    #[inline(always)]
    fn painted(&self, samples: &FootprintSamples, mut levels: FootprintLevels) -> FootprintLevels {
        if let Some(printed) = self.printed {
            paint_printed(self.screen, printed, samples, &mut levels);
        }
        levels
    }
}

/// Printed obstacles drawn over the pheromones at the footprints' 36 samples.
fn paint_printed(
    screen: &ScreenSpec,
    printed: &Printed,
    samples: &FootprintSamples,
    levels: &mut FootprintLevels,
) {
    let points = samples
        .xs
        .iter()
        .zip(&samples.ys)
        .take(4 * FOOTPRINT_POINTS);
    for (k, (&x, &y)) in points.enumerate() {
        if let Some(c) = printed.colour_at(screen, Vec2::new(x, y)) {
            for (ch, v) in c.iter().enumerate() {
                levels[ch][k] = *v as u32;
            }
        }
    }
}
