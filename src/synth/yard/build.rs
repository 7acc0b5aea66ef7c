//! The welding-yard scene generator: stiffened plates, I-beams, T-joints,
//! stacked plates, butt joints with near-collinear edges, fasteners and
//! clamps, laid out as 2.5-D layers of convex facets (later facets in front).
//!
//! Objects are seen from above at an angle: every scene draws one direction
//! `m` in which vertical faces show, so a slab (a plate, a bar) gets a side
//! strip on each side whose outward normal faces `m`, as wide as the slab's
//! height times that cosine. Strips narrower than 4 px are not drawn, so
//! every pair of close parallel edges a scene has is 4 px apart or more
//! (plate thicknesses seen edge-on are 4.5–8 px). Thicknesses are in pixels
//! whatever the image size; lengths scale with it.
//!
//! Grey levels: each face differs from the one beside or beneath it by a
//! drawn contrast: 18 % faint (3–9, don't-care once lit), 37 % low (12–30),
//! the rest 30–90; the light field then scales them.

use super::poly::{Convex, P2};
use super::shade::{Light, Pcg32, Shade, Spot, Texture};
use super::{Facet, YardScene};
use crate::llv::lens::CameraModel;

/// The kinds of object; scene `i` always holds kind `i % KINDS.len()` near
/// its centre, and a few others anywhere.
pub const KINDS: [&str; 6] = [
    "stiffened plate",
    "I-beam",
    "T-joint",
    "stacked plates",
    "butt joint",
    "plate",
];

struct Ctx {
    rng: Pcg32,
    s: f64,
    m: P2,
    facets: Vec<Facet>,
}

fn add(p: P2, q: P2) -> P2 {
    (p.0 + q.0, p.1 + q.1)
}
fn mul(p: P2, k: f64) -> P2 {
    (p.0 * k, p.1 * k)
}
fn dot(p: P2, q: P2) -> f64 {
    p.0 * q.0 + p.1 * q.1
}
fn unit(a: f64) -> P2 {
    (a.cos(), a.sin())
}
fn perp(u: P2) -> P2 {
    (-u.1, u.0)
}

/// The quad `c + s·u + o·v` for `s ∈ {s0, s1}`, `o ∈ {o0, o1}`.
fn band(c: P2, u: P2, v: P2, s: (f64, f64), o: (f64, f64)) -> Vec<P2> {
    let at = |a: f64, b: f64| add(c, add(mul(u, a), mul(v, b)));
    vec![at(s.0, o.0), at(s.1, o.0), at(s.1, o.1), at(s.0, o.1)]
}

impl Ctx {
    fn delta(&mut self) -> f64 {
        let u = self.rng.uniform();
        let d = if u < 0.18 {
            self.rng.range(3.0, 9.0)
        } else if u < 0.55 {
            self.rng.range(12.0, 30.0)
        } else {
            self.rng.range(30.0, 90.0)
        };
        d * self.rng.sign()
    }

    /// A grey level a drawn contrast away from `reference`, kept in 20–230.
    fn near(&mut self, reference: f64) -> f64 {
        let d = self.delta();
        let v = reference + d;
        if (20.0..=230.0).contains(&v) {
            v
        } else {
            (reference - d).clamp(20.0, 230.0)
        }
    }

    fn shade(&mut self, base: f64, pts: &[P2], metal: bool) -> Shade {
        let r = &mut self.rng;
        let c = pts
            .iter()
            .fold((0.0, 0.0), |a, p| add(a, mul(*p, 1.0 / pts.len() as f64)));
        let g = mul(
            unit(r.range(0.0, std::f64::consts::TAU)),
            r.range(0.0, 0.06),
        );
        let mut waves = [(0.0, 0.0, 0.0); 3];
        for w in &mut waves {
            let k = std::f64::consts::TAU / r.range(5.0, 30.0);
            let d = unit(r.range(0.0, std::f64::consts::TAU));
            *w = (k * d.0, k * d.1, r.range(0.0, std::f64::consts::TAU));
        }
        let (wave_amplitude, lattice_amplitude) = if metal {
            (r.range(0.5, 2.0), r.range(0.5, 1.5))
        } else {
            (r.range(1.0, 2.5), r.range(1.0, 2.5))
        };
        let texture = Texture {
            waves,
            wave_amplitude,
            cell: r.range(4.0, 12.0),
            lattice_amplitude,
            seed: r.next_u32(),
        };
        let mut spots = Vec::new();
        if metal && r.chance(0.3) {
            let (x0, y0, x1, y1) = pts.iter().fold(
                (f64::INFINITY, f64::INFINITY, -f64::INFINITY, -f64::INFINITY),
                |b, p| (b.0.min(p.0), b.1.min(p.1), b.2.max(p.0), b.3.max(p.1)),
            );
            for _ in 0..1 + r.below(2) {
                let long = r.range(3.0, 12.0);
                spots.push(Spot {
                    at: (r.range(x0, x1), r.range(y0, y1)),
                    dir: unit(r.range(0.0, std::f64::consts::PI)),
                    sigma_long: long,
                    sigma_short: (long / r.range(1.0, 3.0)).max(2.0),
                    amplitude: r.range(25.0, 80.0),
                });
            }
        }
        Shade {
            base,
            grad: g,
            origin: c,
            spots,
            texture,
        }
    }

    fn push(&mut self, pts: Vec<P2>, level: f64, metal: bool) {
        let shade = self.shade(level, &pts, metal);
        if let Some(poly) = Convex::new(pts) {
            self.facets.push(Facet { poly, shade });
        }
    }

    /// A slab whose top face is `top`: side strips where its sides face the
    /// view direction (the widest `max_width` px, none under 4 px), then the
    /// top face.
    fn slab(&mut self, top: Vec<P2>, level: f64, max_width: f64, metal: bool) {
        let Some(c) = Convex::new(top.clone()) else {
            return;
        };
        let m = self.m;
        let best = c
            .planes
            .iter()
            .map(|pl| -(pl.a * m.0 + pl.b * m.1))
            .fold(0.0, f64::max);
        if best > 0.05 {
            let height = max_width / best;
            let sides: Vec<(P2, P2, f64)> = c
                .edges()
                .zip(&c.planes)
                .map(|((p, q), pl)| (p, q, -(pl.a * m.0 + pl.b * m.1) * height))
                .collect();
            for (p, q, w) in sides {
                if w >= 4.0 {
                    let lv = self.near(level);
                    let hm = mul(m, height);
                    self.push(vec![p, q, add(q, hm), add(p, hm)], lv, metal);
                }
            }
        }
        self.push(top, level, metal);
    }

    fn rect(&mut self, c: P2, u: P2, hl: f64, hw: f64, jitter: f64) -> Vec<P2> {
        band(c, u, perp(u), (-hl, hl), (-hw, hw))
            .into_iter()
            .map(|p| {
                let j = (
                    self.rng.range(-jitter, jitter),
                    self.rng.range(-jitter, jitter),
                );
                add(p, j)
            })
            .collect()
    }

    fn plate_dims(&mut self) -> (f64, f64) {
        let s = self.s;
        (
            self.rng.range(90.0, 230.0) * s,
            self.rng.range(50.0, 150.0) * s,
        )
    }

    fn plate(&mut self, c: P2, u: P2, floor: f64) -> (f64, f64, f64) {
        let (hl, hw) = self.plate_dims();
        let pts = self.rect(c, u, hl, hw, 1.5);
        let level = self.near(floor);
        let t = self.rng.range(4.5, 8.0);
        self.slab(pts, level, t, true);
        (hl, hw, level)
    }

    fn stacked(&mut self, c: P2, u: P2, floor: f64) {
        let (hl, hw, level) = self.plate(c, u, floor);
        let s = self.s;
        let mut d = [0.0; 4];
        for x in &mut d {
            *x = if self.rng.chance(0.4) {
                self.rng.range(4.5, 8.0)
            } else {
                self.rng.range(12.0, 50.0) * s
            };
        }
        let u2 = {
            let a = u.1.atan2(u.0) + self.rng.range(-2.0, 2.0).to_radians();
            unit(a)
        };
        let v = perp(u);
        let cc = add(
            c,
            add(mul(u, 0.5 * (d[0] - d[1])), mul(v, 0.5 * (d[2] - d[3]))),
        );
        let (hl2, hw2) = (hl - 0.5 * (d[0] + d[1]), hw - 0.5 * (d[2] + d[3]));
        if hl2 > 10.0 && hw2 > 10.0 {
            let pts = self.rect(cc, u2, hl2, hw2, 0.5);
            let l2 = self.near(level);
            let t = self.rng.range(4.5, 8.0);
            self.slab(pts, l2, t, true);
        }
    }

    fn stiffened(&mut self, c: P2, u: P2, floor: f64) {
        let (hl, hw, level) = self.plate(c, u, floor);
        let along = self.rng.chance(0.5);
        let (dir, half_len, across) = if along {
            (u, hl, hw)
        } else {
            (perp(u), hw, hl)
        };
        let n = 1 + self.rng.below(3);
        let side = perp(dir);
        for k in 0..n {
            let off = across * ((k as f64 + 1.0) / (n as f64 + 1.0) * 2.0 - 1.0);
            let centre = add(c, mul(side, off));
            let end_gap = self.rng.range(0.0, 10.0);
            let hw_bar = self.rng.range(2.5, 4.5);
            let pts = self.rect(centre, dir, half_len - end_gap, hw_bar, 0.2);
            let lv = self.near(level);
            let web = self.rng.range(15.0, 40.0) * self.s.max(0.5);
            self.slab(pts, lv, web, true);
        }
    }

    fn i_beam(&mut self, c: P2, u: P2, floor: f64) {
        let s = self.s;
        let mut v = perp(u);
        if dot(v, self.m) < 0.0 {
            v = mul(v, -1.0);
        }
        let hl = self.rng.range(200.0, 420.0) * s;
        let widths = [
            self.rng.range(14.0, 30.0) * s,
            self.rng.range(4.5, 8.0),
            self.rng.range(25.0, 60.0) * s,
            self.rng.range(4.5, 8.0),
        ];
        let total: f64 = widths.iter().sum();
        let mut o = -0.5 * total;
        let flange = self.near(floor);
        let web = self.near(floor);
        let levels = [flange, 0.0, web, 0.0];
        for (k, w) in widths.iter().enumerate() {
            let lv = match k {
                0 | 2 => levels[k],
                1 => self.near(flange),
                _ => self.near(web),
            };
            let pts = band(c, u, v, (-hl, hl), (o, o + w));
            self.push(pts, lv, true);
            o += w;
        }
    }

    fn t_joint(&mut self, c: P2, u: P2, floor: f64) {
        let (hl, _, base) = self.plate(c, u, floor);
        let s = self.s;
        let mut v = perp(u);
        if dot(v, self.m) > 0.0 {
            v = mul(v, -1.0);
        }
        let len = hl * self.rng.range(0.5, 0.9);
        let bead = self.rng.range(5.0, 8.0);
        let height = self.rng.range(40.0, 110.0) * s;
        let top = self.rng.range(4.5, 8.0);
        let lb = self.near(base);
        self.push(band(c, u, v, (-len, len), (-bead, 0.0)), lb, true);
        if let Some(f) = self.facets.last_mut() {
            // Weld ripples across the bead.
            let k = std::f64::consts::TAU / 4.0;
            f.shade.texture.waves[0] = (k * u.0, k * u.1, 0.0);
            f.shade.texture.wave_amplitude = 3.0;
        }
        let lf = self.near(base);
        self.push(band(c, u, v, (-len, len), (0.0, height)), lf, true);
        let lt = self.near(lf);
        self.push(band(c, u, v, (-len, len), (height, height + top)), lt, true);
    }

    fn butt(&mut self, c: P2, u: P2, floor: f64) {
        let (hl1, hw) = self.plate_dims();
        let hl2 = self.rng.range(60.0, 200.0) * self.s;
        let gap = if self.rng.chance(0.5) {
            0.0
        } else {
            self.rng.range(4.0, 10.0)
        };
        let turn = self.rng.sign() * self.rng.range(0.4, 2.5);
        let shift = self.rng.sign() * self.rng.range(0.8, 3.0);
        let u2 = unit(u.1.atan2(u.0) + turn.to_radians());
        let v = perp(u);
        let c1 = add(c, mul(u, -(hl1 + 0.5 * gap)));
        let c2 = add(add(c, mul(u2, hl2 + 0.5 * gap)), mul(v, shift));
        let t = self.rng.range(4.5, 8.0);
        let l1 = self.near(floor);
        let p1 = self.rect(c1, u, hl1, hw, 0.0);
        self.slab(p1, l1, t, true);
        let hw2 = hw + self.rng.range(-3.0, 3.0);
        let l2 = self.near(l1);
        let p2 = self.rect(c2, u2, hl2, hw2, 0.0);
        self.slab(p2, l2, t, true);
    }

    /// A washer (a 20-gon: sides under 6 px, so never a true edge) with a
    /// hexagon nut on it.
    fn fastener(&mut self, c: P2, floor: f64) {
        let r = self.rng.range(8.0, 13.0);
        let a0 = self.rng.range(0.0, 1.0);
        let ring = |n: usize, r: f64, a0: f64| -> Vec<P2> {
            (0..n)
                .map(|k| {
                    let a = a0 + std::f64::consts::TAU * k as f64 / n as f64;
                    add(c, mul(unit(a), r))
                })
                .collect()
        };
        let lw = self.near(floor);
        self.push(ring(20, r, a0), lw, true);
        let ln = self.near(lw);
        let rn = self.rng.range(6.5, 0.75 * r);
        let a1 = self.rng.range(0.0, 1.0);
        self.push(ring(6, rn, a1), ln, true);
    }

    /// A small clamp block astride an edge already drawn.
    fn clamp(&mut self, floor: f64) {
        let cands: Vec<P2> = self
            .facets
            .iter()
            .skip(1)
            .filter(|f| (f.poly.bbox[2] - f.poly.bbox[0]) > 30.0)
            .flat_map(|f| f.poly.edges().map(|(p, q)| mul(add(p, q), 0.5)))
            .collect();
        if cands.is_empty() {
            return;
        }
        let c = cands[self.rng.below(cands.len())];
        let u = unit(self.rng.range(0.0, std::f64::consts::PI));
        let (hl, hw) = (self.rng.range(12.0, 25.0), self.rng.range(8.0, 16.0));
        let pts = self.rect(c, u, hl, hw, 0.5);
        let lv = self.near(floor.max(60.0));
        let t = self.rng.range(6.0, 12.0);
        self.slab(pts, lv, t, true);
    }

    fn object(&mut self, kind: usize, c: P2, floor: f64) {
        let u = unit(self.rng.range(0.0, std::f64::consts::PI));
        match kind {
            0 => self.stiffened(c, u, floor),
            1 => self.i_beam(c, u, floor),
            2 => self.t_joint(c, u, floor),
            3 => self.stacked(c, u, floor),
            4 => self.butt(c, u, floor),
            _ => {
                self.plate(c, u, floor);
            }
        }
    }
}

/// Scene `index` of the family for images of `size × size` px.
pub fn scene(index: usize, size: usize, seed: u64) -> YardScene {
    let mut rng = Pcg32::new(seed, 0x7A5D_0000 + index as u64);
    let w = size as f64;
    let s = w / 512.0;
    let m = unit(rng.range(0.0, std::f64::consts::TAU));
    let mut ctx = Ctx {
        rng,
        s,
        m,
        facets: Vec::new(),
    };
    let floor = ctx.rng.range(45.0, 95.0);
    let margin = 64.0;
    let whole = vec![
        (-margin, -margin),
        (w + margin, -margin),
        (w + margin, w + margin),
        (-margin, w + margin),
    ];
    ctx.push(whole, floor, false);
    let extras = 1 + ctx.rng.below(3);
    let primary = index % KINDS.len();
    let mut kinds = Vec::new();
    // Extras first (behind), the scene's own kind in front near the centre.
    for _ in 0..extras {
        let k = ctx.rng.below(KINDS.len());
        let c = (ctx.rng.range(-0.1, 1.1) * w, ctx.rng.range(-0.1, 1.1) * w);
        ctx.object(k, c, floor);
        kinds.push(KINDS[k]);
    }
    let c = (ctx.rng.range(0.3, 0.7) * w, ctx.rng.range(0.3, 0.7) * w);
    ctx.object(primary, c, floor);
    kinds.push(KINDS[primary]);
    let fasteners = ctx.rng.below(3);
    for _ in 0..fasteners {
        let c = (ctx.rng.range(0.1, 0.9) * w, ctx.rng.range(0.1, 0.9) * w);
        ctx.fastener(c, floor);
    }
    kinds.extend(std::iter::repeat_n("fastener", fasteners));
    let clamps = ctx.rng.below(3);
    for _ in 0..clamps {
        ctx.clamp(floor);
    }
    kinds.extend(std::iter::repeat_n("clamp", clamps));
    let r = &mut ctx.rng;
    let sx = 5.12 / w;
    let k1 = r.sign() * r.range(6e-4, 1.2e-3);
    let mut g = [0.0; 4];
    for x in &mut g {
        *x = r.range(-2e-4, 2e-4);
    }
    let lens = CameraModel {
        cx: 0.5 * (w - 1.0) + r.range(-6.0, 6.0) * s,
        cy: 0.5 * (w - 1.0) + r.range(-6.0, 6.0) * s,
        sx,
        sy: sx,
        f: 8.0,
        distortion: Some([k1, g[0], g[1], g[2], g[3]]),
        radial: [0.0; 2],
    };
    let light = Light {
        spot: (r.range(0.2, 0.8) * w, r.range(0.2, 0.8) * w),
        spot_radius: r.range(0.35, 0.8) * w,
        spot_floor: r.range(0.35, 0.7),
        centre: (lens.cx, lens.cy),
        focal_px: lens.f / sx,
    };
    let defocus_sigma = r.range(0.7, 1.5);
    YardScene {
        width: size,
        height: size,
        facets: ctx.facets,
        light,
        defocus_sigma,
        lens,
        kinds,
    }
}
