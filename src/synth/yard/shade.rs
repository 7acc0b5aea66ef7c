//! Radiance of the yard scenes: what each facet emits at a point, and the
//! light field over the whole image.
//!
//! A facet's radiance is `L(x, y) · (base + g·(p − o) + spots + texture)`:
//! a linear shading gradient (a plate tilted against a lamp), specular spots
//! (anisotropic Gaussian highlights on bare steel, up to saturation), and a
//! low-amplitude texture (three sinusoids of 5–30 px and a smoothed lattice
//! noise: mill scale, grinding marks, concrete). `L` multiplies in a
//! spot-light's Gaussian falloff and the lens's cos⁴ vignetting about the
//! optical centre, so the same step in albedo shows a smaller contrast in
//! the dim corners. The smooth part (everything but the texture) is what the
//! ground truth measures contrast with.
//!
//! Random numbers here come from PCG32 (O'Neill 2014), a generator
//! unrelated to the cube family's SplitMix64, and Gaussian deviates from
//! Marsaglia's polar method rather than Box–Muller.

/// PCG32 (XSH-RR, 64-bit state): small, fast, statistically sound.
#[derive(Clone, Debug)]
pub struct Pcg32 {
    state: u64,
    inc: u64,
    spare: Option<f64>,
}

impl Pcg32 {
    pub fn new(seed: u64, stream: u64) -> Pcg32 {
        let mut r = Pcg32 {
            state: 0,
            inc: (stream << 1) | 1,
            spare: None,
        };
        r.next_u32();
        r.state = r.state.wrapping_add(seed);
        r.next_u32();
        r
    }

    pub fn next_u32(&mut self) -> u32 {
        let old = self.state;
        self.state = old
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(self.inc);
        let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
        let rot = (old >> 59) as u32;
        xorshifted.rotate_right(rot)
    }

    /// Uniform in `[0, 1)` (53 bits from two outputs).
    pub fn uniform(&mut self) -> f64 {
        let hi = u64::from(self.next_u32()) << 21;
        let lo = u64::from(self.next_u32() >> 11);
        (hi | lo) as f64 / (1u64 << 53) as f64
    }

    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.uniform()
    }

    /// `true` with probability `p`.
    pub fn chance(&mut self, p: f64) -> bool {
        self.uniform() < p
    }

    /// An integer in `0..n` (0 when `n == 0`).
    pub fn below(&mut self, n: usize) -> usize {
        if n == 0 {
            0
        } else {
            ((self.uniform() * n as f64) as usize).min(n - 1)
        }
    }

    /// ±1.
    pub fn sign(&mut self) -> f64 {
        if self.chance(0.5) { 1.0 } else { -1.0 }
    }

    /// A standard normal deviate (Marsaglia's polar method).
    pub fn gauss(&mut self) -> f64 {
        if let Some(s) = self.spare.take() {
            return s;
        }
        loop {
            let u = 2.0 * self.uniform() - 1.0;
            let v = 2.0 * self.uniform() - 1.0;
            let s = u * u + v * v;
            if s > 0.0 && s < 1.0 {
                let m = (-2.0 * s.ln() / s).sqrt();
                self.spare = Some(v * m);
                return u * m;
            }
        }
    }
}

/// The light over the image: a spot's Gaussian falloff times cos⁴
/// vignetting.
#[derive(Clone, Debug, PartialEq)]
pub struct Light {
    /// Spot centre (ideal px), radius (σ of the falloff, px) and the floor it
    /// falls to far away (fraction).
    pub spot: (f64, f64),
    pub spot_radius: f64,
    pub spot_floor: f64,
    /// Optical centre (px) and focal length (px) of the vignetting.
    pub centre: (f64, f64),
    pub focal_px: f64,
}

impl Light {
    pub fn at(&self, x: f64, y: f64) -> f64 {
        let (dx, dy) = (x - self.spot.0, y - self.spot.1);
        let r2 = (dx * dx + dy * dy) / (self.spot_radius * self.spot_radius);
        let spot = self.spot_floor + (1.0 - self.spot_floor) * (-0.5 * r2).exp();
        let (vx, vy) = (x - self.centre.0, y - self.centre.1);
        let t = 1.0 + (vx * vx + vy * vy) / (self.focal_px * self.focal_px);
        spot / (t * t)
    }
}

/// A specular highlight: an anisotropic Gaussian.
#[derive(Clone, Debug, PartialEq)]
pub struct Spot {
    pub at: (f64, f64),
    /// Unit direction of the long axis.
    pub dir: (f64, f64),
    pub sigma_long: f64,
    pub sigma_short: f64,
    pub amplitude: f64,
}

/// Low-amplitude surface texture.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    /// `(kx, ky, phase)` of three sinusoids (radians per px).
    pub waves: [(f64, f64, f64); 3],
    pub wave_amplitude: f64,
    /// Lattice noise: cell size (px), amplitude, hash seed.
    pub cell: f64,
    pub lattice_amplitude: f64,
    pub seed: u32,
}

impl Texture {
    pub fn at(&self, x: f64, y: f64) -> f64 {
        let mut w = 0.0;
        for &(kx, ky, ph) in &self.waves {
            w += (kx * x + ky * y + ph).sin();
        }
        let mut v = self.wave_amplitude * w / 3.0;
        if self.lattice_amplitude > 0.0 {
            v += self.lattice_amplitude * lattice(x / self.cell, y / self.cell, self.seed);
        }
        v
    }
}

/// Smoothed value noise in `[-1, 1]` on a unit lattice.
fn lattice(x: f64, y: f64, seed: u32) -> f64 {
    let (fx, fy) = (x.floor(), y.floor());
    let (tx, ty) = (x - fx, y - fy);
    let (sx, sy) = (tx * tx * (3.0 - 2.0 * tx), ty * ty * (3.0 - 2.0 * ty));
    let (ix, iy) = (fx as i64, fy as i64);
    let h = |i: i64, j: i64| hash(i, j, seed);
    let a = h(ix, iy) + (h(ix + 1, iy) - h(ix, iy)) * sx;
    let b = h(ix, iy + 1) + (h(ix + 1, iy + 1) - h(ix, iy + 1)) * sx;
    a + (b - a) * sy
}

fn hash(i: i64, j: i64, seed: u32) -> f64 {
    let mut z = (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
        ^ (j as u64).wrapping_mul(0xC2B2_AE3D_27D4_EB4F)
        ^ u64::from(seed).wrapping_mul(0x1656_67B1_9E37_79F9);
    z ^= z >> 29;
    z = z.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z ^= z >> 32;
    (z >> 11) as f64 / (1u64 << 52) as f64 - 1.0
}

/// What one facet emits (before the light field).
#[derive(Clone, Debug, PartialEq)]
pub struct Shade {
    pub base: f64,
    /// Gradient (grey levels per px) about `origin`.
    pub grad: (f64, f64),
    pub origin: (f64, f64),
    pub spots: Vec<Spot>,
    pub texture: Texture,
}

impl Shade {
    /// Everything but the texture.
    pub fn smooth(&self, x: f64, y: f64) -> f64 {
        let mut v =
            self.base + self.grad.0 * (x - self.origin.0) + self.grad.1 * (y - self.origin.1);
        for s in &self.spots {
            let (dx, dy) = (x - s.at.0, y - s.at.1);
            let a = dx * s.dir.0 + dy * s.dir.1;
            let b = -dx * s.dir.1 + dy * s.dir.0;
            let q = (a / s.sigma_long).powi(2) + (b / s.sigma_short).powi(2);
            if q < 40.0 {
                v += s.amplitude * (-0.5 * q).exp();
            }
        }
        v.max(0.0)
    }

    pub fn full(&self, x: f64, y: f64) -> f64 {
        (self.smooth(x, y) + self.texture.at(x, y)).max(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pcg_repeats_and_its_normals_have_unit_variance() {
        let (mut a, mut b) = (Pcg32::new(5, 3), Pcg32::new(5, 3));
        assert_eq!(a.next_u32(), b.next_u32());
        assert_ne!(Pcg32::new(5, 4).next_u32(), Pcg32::new(5, 3).next_u32());
        let n = 20000;
        let xs: Vec<f64> = (0..n).map(|_| a.gauss()).collect();
        let mean = xs.iter().sum::<f64>() / n as f64;
        let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n as f64;
        assert!(
            mean.abs() < 0.03 && (var - 1.0).abs() < 0.05,
            "{mean} {var}"
        );
    }

    #[test]
    fn light_falls_off_from_the_spot_and_the_centre() {
        let l = Light {
            spot: (100.0, 100.0),
            spot_radius: 80.0,
            spot_floor: 0.5,
            centre: (100.0, 100.0),
            focal_px: 400.0,
        };
        assert!((l.at(100.0, 100.0) - 1.0).abs() < 1e-12);
        assert!(l.at(300.0, 100.0) < 0.55 * l.at(100.0, 100.0));
        assert!(l.at(300.0, 100.0) > 0.3);
    }

    #[test]
    fn lattice_noise_is_bounded_and_continuous() {
        for k in 0..1000 {
            let x = k as f64 * 0.37;
            let v = lattice(x, 0.5 * x, 9);
            assert!((-1.0..=1.0).contains(&v));
            assert!((lattice(x + 1e-6, 0.5 * x, 9) - v).abs() < 1e-4);
        }
    }
}
