//! No per-image heap growth once warmed up: a counting global allocator
//! watches a second and third run of the whole pipeline (lens correction
//! with a precomputed map, edges, lines, CONNECT) in a warm `Workspace`,
//! for one image and for several lightings plus an ambient image (the
//! photometric combination of llv.md §2.6, with and without lens).
//! This file is its own test binary, so the allocator sees only this test.
//!
//! `GlobalAlloc` is an unsafe trait: this file is the one place of the crate
//! that allows `unsafe_code` (Cargo.toml denies it everywhere else). The
//! impl only forwards to `System` and counts.

#![allow(unsafe_code)]

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

use vss::llv::lens::{CameraModel, LensMap};
use vss::llv::pipeline::{Input, Workspace};
use vss::llv::{GreyImage, Params};

#[path = "support/llv_scene.rs"]
mod llv_scene;

struct Counting;

static ALLOCS: AtomicUsize = AtomicUsize::new(0);
static BYTES: AtomicUsize = AtomicUsize::new(0);

// SAFETY: every method forwards to `System` with the caller's arguments
// unchanged; the counters are atomics and never allocate.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCS.fetch_add(1, Ordering::Relaxed);
        BYTES.fetch_add(layout.size(), Ordering::Relaxed);
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCS.fetch_add(1, Ordering::Relaxed);
        BYTES.fetch_add(new_size, Ordering::Relaxed);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Allocations (count, bytes) made by `f`. The tests of this binary run
/// one after the other (`a_single_test_thread` below) so the counts are
/// only `f`'s.
fn allocations(f: impl FnOnce()) -> (usize, usize) {
    let (a0, b0) = (ALLOCS.load(Ordering::SeqCst), BYTES.load(Ordering::SeqCst));
    f();
    let (a1, b1) = (ALLOCS.load(Ordering::SeqCst), BYTES.load(Ordering::SeqCst));
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
    };
    LensMap::new(&m, n, n)
}

/// One test function runs both cases in turn: the allocator counts are
/// process-wide, and a second test thread would allocate into them.
#[test]
fn a_single_test_thread() {
    a_warm_workspace_does_not_allocate();
    a_warm_workspace_does_not_allocate_for_several_lightings();
}

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

fn a_warm_workspace_does_not_allocate() {
    let n = 256;
    let images = [
        llv_scene::scene(n, n, 2.0, 1),
        llv_scene::scene(n, n, 2.0, 2),
        llv_scene::scene(n, n, 5.0, 3),
    ];
    let map = camera(n);
    let p = Params::default();
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
    let (a0, b0) = (ALLOCS.load(Ordering::SeqCst), BYTES.load(Ordering::SeqCst));
    for k in [0, 1, 0, 1] {
        ws.run(&input(k), &p).unwrap();
    }
    let (a1, b1) = (ALLOCS.load(Ordering::SeqCst), BYTES.load(Ordering::SeqCst));
    assert_eq!(
        a1 - a0,
        0,
        "{} allocations ({} bytes) in warm runs",
        a1 - a0,
        b1 - b0
    );
    let corrected = &ws.outputs().corrected;
    assert!(
        corrected.len() == 1 && corrected[0].valid_mask().is_some(),
        "lens correction ran, with invalid corners"
    );
}
