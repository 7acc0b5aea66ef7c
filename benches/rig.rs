//! Rig benchmarks: frame transfer from the simulated grabber over a real
//! pseudo-terminal (bytes per second; the wire bytes per payload byte are
//! printed once), a full four-lighting capture of one image on the
//! simulated cell, and the cost of rendering one simulated view.
//!
//! Run: `cargo bench --bench rig`.

use std::sync::Once;

use divan::counter::BytesCount;
use divan::{Bencher, black_box};
use vss::rig::Cell;
use vss::rig::grabber::{ClientConfig, FrameGrabber, VsgClient};
use vss::rig::sim::{SimCell, SimOptions, cell_profile, render};

fn main() {
    divan::main();
}

static OVERHEAD: Once = Once::new();

/// FREEZE once, then READ the 512 × 512 frame in the profile's default
/// 16 KiB blocks, CRCs checked.
#[divan::bench(sample_count = 20)]
fn transfer_512x512_over_pty(b: Bencher) {
    let sim = SimCell::start(SimOptions::new(512, 512)).expect("sim");
    let cfg = ClientConfig::from_profile(&vss::profile::GrabberConfig::default());
    let mut g = VsgClient::open(sim.grabber_path(), 921_600, cfg).expect("connect");
    g.freeze().expect("freeze");
    let before = g.wire_stats();
    g.transfer(&mut |_, _| true).expect("transfer");
    let after = g.wire_stats();
    OVERHEAD.call_once(|| {
        let wire = (after.tx + after.rx) - (before.tx + before.rx);
        let payload = after.payload - before.payload;
        eprintln!(
            "transfer: {wire} wire bytes for {payload} payload bytes = {:.4} per payload byte (block 16384)",
            wire as f64 / payload as f64
        );
    });
    b.counter(BytesCount::new(512usize * 512))
        .bench_local(|| black_box(g.transfer(&mut |_, _| true).expect("transfer")));
}

/// `vss grab --lighting a,b,c,e` on the embedded simulated cell at 512 × 512:
/// switch (and read back), settle, freeze, transfer, four times. Renders are
/// cached after the first round, as in a survey.
#[divan::bench(args = [0, 200], sample_count = 5)]
fn four_lighting_capture(b: Bencher, settle_ms: u64) {
    let mut p = cell_profile(512, 512);
    p.relay.settle_ms = settle_ms;
    let mut cell = Cell::open(&p).expect("cell");
    for l in ['a', 'b', 'c', 'e'] {
        cell.capture(1, l, &mut |_, _| true).expect("warm");
    }
    b.bench_local(|| {
        for l in ['a', 'b', 'c', 'e'] {
            black_box(cell.capture(1, l, &mut |_, _| true).expect("capture"));
        }
    });
}

/// Rendering one noise-free 512 × 512 view (what the frame cache saves).
#[divan::bench(sample_count = 5)]
fn render_view_512(b: Bencher) {
    let o = SimOptions::new(512, 512);
    b.bench_local(|| black_box(render::render_clean(&o, 2, 0b1)));
}
