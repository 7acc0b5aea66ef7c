//! No per-image heap growth once warmed up: a counting global allocator
//! watches a second and third run of the whole pipeline (lens correction
//! with a precomputed map, edges, lines, CONNECT) in a warm `Workspace`,
//! for one image and for several lightings plus an ambient image (the
//! photometric combination of llv.md §2.6, with and without lens).
//! The allocator is the whole test binary's, and counts per thread: the
//! other tests running beside these on other threads do not touch the
//! counts, and the pipeline runs on the calling thread (`threads = 1`).
//!
//! `GlobalAlloc` is an unsafe trait: this module is the one place of the
//! crate that allows `unsafe_code` (Cargo.toml denies it everywhere else).
//! The impl only forwards to `System` and counts.

#![allow(unsafe_code)]

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use vss::llv::lens::{CameraModel, LensMap};
use vss::llv::pipeline::{Input, Workspace};
use vss::llv::{GreyImage, Params};

use crate::support::llv_scene;

struct Counting;

thread_local! {
    /// This thread's allocations: (count, bytes). A `const` thread-local of
    /// a `Cell` has no destructor and never allocates.
    static COUNTS: Cell<(usize, usize)> = const { Cell::new((0, 0)) };
}

fn count(bytes: usize) {
    // `try_with`: during a thread's teardown the slot may be gone.
    let _ = COUNTS.try_with(|c| {
        let (n, b) = c.get();
        c.set((n + 1, b + bytes));
    });
}

fn counts() -> (usize, usize) {
    COUNTS.with(Cell::get)
}

// SAFETY: every method forwards to `System` with the caller's arguments
// unchanged; the counters are thread-local cells and never allocate.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count(layout.size());
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count(new_size);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Allocations (count, bytes) made by `f` on this thread.
fn allocations(f: impl FnOnce()) -> (usize, usize) {
    let (a0, b0) = counts();
    f();
    let (a1, b1) = counts();
    (a1 - a0, b1 - b0)
}

fn camera(n: usize) -> LensMap {
    let m = CameraModel {
        cx: 130.0,
        cy: 126.0,
        sx: 0.0172,
        sy: 0.0166,
        f: 8.5,
        // Pincushion: the corners sample outside the grabbed image, so the
        // corrected images carry a validity mask (whose buffer is reused).
        distortion: Some([1.2e-3, 1.0e-4, -8.0e-5, 5.0e-5, 2.0e-5]),
        radial: [0.0; 2],
    };
    LensMap::new(&m, n, n)
}

#[test]
fn a_warm_workspace_does_not_allocate_for_several_lightings() {
    let n = 256;
    // Two takes of four lightings each (other noise) plus their ambient
    // images: the same scene at a quarter of the brightness.
    let views: Vec<(Vec<GreyImage>, GreyImage)> = (0..2u64)
        .map(|v| {
            let lit = (0..4)
                .map(|k| llv_scene::scene(n, n, 2.0 + k as f64, 10 * v + k))
                .collect();
            let amb = llv_scene::scene(n, n, 3.0, 10 * v + 9);
            let dim = amb.data().iter().map(|&g| g / 4).collect();
            (lit, GreyImage::new(n, n, dim).unwrap())
        })
        .collect();
    let map = camera(n);
    let p = Params::default();
    for lens in [None, Some(&map)] {
        let input = |k: usize| Input {
            images: &views[k].0,
            ambient: Some(&views[k].1),
            lens,
        };
        let mut ws = Workspace::new();
        for k in [0, 1, 0] {
            ws.run(&input(k), &p).unwrap();
        }
        assert!(ws.outputs().lines.len() > 10, "the views have lines");
        let (count, bytes) = allocations(|| {
            for k in [1, 0, 1, 0] {
                ws.run(&input(k), &p).unwrap();
            }
        });
        assert_eq!(
            count,
            0,
            "{count} allocations ({bytes} bytes) in warm runs, lens: {}",
            lens.is_some()
        );
        assert_eq!(
            ws.outputs().corrected.len(),
            if lens.is_some() { 4 } else { 0 },
            "lens correction ran only when asked"
        );
    }
}

#[test]
fn a_warm_workspace_does_not_allocate() {
    let n = 256;
    let images = [
        llv_scene::scene(n, n, 2.0, 1),
        llv_scene::scene(n, n, 2.0, 2),
        llv_scene::scene(n, n, 5.0, 3),
    ];
    let map = camera(n);
    // The defaults, and one point a scan line: every region then has more
    // candidates than it keeps, and the limits are selected.
    let mut crowded = Params::default();
    crowded.edges.per_region = 1;
    for p in [Params::default(), crowded] {
        let input = |k: usize| Input {
            images: std::slice::from_ref(&images[k]),
            ambient: None,
            lens: Some(&map),
        };
        let mut ws = Workspace::new();
        // Warm up on the busiest image so every buffer reaches its size.
        for k in [2, 0, 1] {
            ws.run(&input(k), &p).unwrap();
        }
        let lines_before = ws.outputs().lines.len();
        assert!(lines_before > 10, "the scene has lines");
        let (count, bytes) = allocations(|| {
            for k in [0, 1, 0, 1] {
                ws.run(&input(k), &p).unwrap();
            }
        });
        assert_eq!(
            count, 0,
            "{count} allocations ({bytes} bytes) in warm runs, M = {}",
            p.edges.per_region
        );
        let corrected = &ws.outputs().corrected;
        assert!(
            corrected.len() == 1 && corrected[0].valid_mask().is_some(),
            "lens correction ran, with invalid corners"
        );
    }
}
