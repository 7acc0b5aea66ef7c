use super::*;

fn seg(ax: f64, ay: f64, bx: f64, by: f64) -> Segment {
    Segment::new(Point::new(ax, ay), Point::new(bx, by))
}

#[test]
fn perfect_detection_scores_one() {
    let truth = vec![seg(10.0, 10.0, 110.0, 10.0), seg(10.0, 10.0, 10.0, 60.0)];
    let m = score(&truth, &truth);
    assert!((m.recall - 1.0).abs() < 1e-12);
    assert!((m.precision - 1.0).abs() < 1e-12);
    assert!(m.endpoint_mean < 1e-12 && m.angle_mean_deg < 1e-9);
}

#[test]
fn half_covered_edge_and_a_noise_line() {
    let truth = vec![seg(0.0, 0.0, 100.0, 0.0)];
    // Covers x 0..50 at 1 px off; the noise line is far away.
    let det = vec![seg(0.0, 1.0, 50.0, 1.0), seg(0.0, 30.0, 50.0, 30.0)];
    let m = score(&det, &truth);
    assert!((m.recall - 0.5).abs() < 1e-9, "{m:?}");
    assert!((m.precision - 0.5).abs() < 1e-9, "{m:?}");
    assert!((m.endpoint_mean - 1.0).abs() < 1e-9);
    assert_eq!(m.supporting, 1);
}

#[test]
fn overlapping_detections_are_not_counted_twice() {
    let truth = vec![seg(0.0, 0.0, 100.0, 0.0)];
    let det = vec![seg(0.0, 0.5, 60.0, 0.5), seg(40.0, -0.5, 80.0, -0.5)];
    let m = score(&det, &truth);
    assert!((m.recall - 0.8).abs() < 1e-9, "{m:?}");
    assert!((m.precision - 1.0).abs() < 1e-9);
}

#[test]
fn support_stops_two_px_beyond_the_true_end_and_at_the_angle_limit() {
    let truth = vec![seg(0.0, 0.0, 100.0, 0.0)];
    // Runs 20 px past the end: only 2 px of the overshoot supports.
    let m = score(&[seg(80.0, 0.0, 120.0, 0.0)], &truth);
    assert!((m.precision - 22.0 / 40.0).abs() < 1e-9, "{m:?}");
    assert!((m.recall - 0.2).abs() < 1e-9);
    // 4° off: no support at all; 2° off: support where within 2 px.
    let r = 50.0;
    let t4 = 4f64.to_radians();
    let off = seg(50.0, 0.0, 50.0 + r * t4.cos(), -r * t4.sin());
    assert_eq!(score(&[off], &truth).precision, 0.0);
    let t2 = 2f64.to_radians();
    let near = seg(0.0, 0.0, 100.0 * t2.cos(), -100.0 * t2.sin());
    let m = score(&[near], &truth);
    // Within 2 px while 100·sin(2°)·s/100 ≤ 2 → s ≤ 2/sin 2° ≈ 57.3.
    let expect = 2.0 / t2.sin() / 100.0;
    assert!((m.precision - expect).abs() < 1e-6, "{m:?} vs {expect}");
    assert!((m.angle_mean_deg - 2.0).abs() < 1e-9);
}

#[test]
fn pooled_scores_weight_by_length() {
    let t1 = vec![seg(0.0, 0.0, 100.0, 0.0)];
    let t2 = vec![seg(0.0, 0.0, 300.0, 0.0)];
    let m = score_all(&[(t1.clone(), t1), (vec![], t2)]);
    assert!((m.recall - 0.25).abs() < 1e-9);
    assert!((m.precision - 1.0).abs() < 1e-9);
    assert_eq!(percentile(&[1.0, 2.0, 3.0, 4.0], 0.5), 2.0);
}

fn with_contrast(mut s: Segment, c: f64) -> Segment {
    s.response = c;
    s
}

fn tally(det: &[Segment], truth: &[Segment], dc: &[Segment]) -> Metrics {
    let mut t = Tally::default();
    t.add_with(det, truth, dc);
    t.metrics()
}

#[test]
fn detections_of_dont_care_edges_count_neither_way() {
    let truth = vec![seg(0.0, 0.0, 100.0, 0.0)];
    let faint = vec![seg(0.0, 30.0, 50.0, 30.0)];
    let det = vec![
        seg(0.0, 0.5, 100.0, 0.5),
        seg(0.0, 30.5, 50.0, 30.5),
        seg(0.0, 60.0, 50.0, 60.0),
    ];
    let m = tally(&det, &truth, &faint);
    assert!((m.recall - 1.0).abs() < 1e-12);
    assert!((m.precision - 100.0 / 150.0).abs() < 1e-9, "{m:?}");
    assert!((m.dont_care_length - 50.0).abs() < 1e-9);
    assert!((m.true_length - 100.0).abs() < 1e-12);
    // Without the don't-care edge, the faint line's detection is false.
    let plain = tally(&det, &truth, &[]);
    assert!((plain.precision - 0.5).abs() < 1e-9, "{plain:?}");
    // Missing a don't-care edge costs nothing.
    let m = tally(&det[..1], &truth, &faint);
    assert!((m.precision - 1.0).abs() < 1e-12 && (m.recall - 1.0).abs() < 1e-12);
}

#[test]
fn a_line_running_on_into_the_border_band_loses_nothing() {
    // The true edge ends where the border band starts; beyond it the same
    // edge is don't-care.
    let truth = vec![seg(0.0, 0.0, 100.0, 0.0)];
    let band = vec![seg(100.0, 0.0, 140.0, 0.0)];
    let det = vec![seg(0.0, 0.0, 140.0, 0.0)];
    let m = tally(&det, &truth, &band);
    assert!((m.precision - 1.0).abs() < 1e-9, "{m:?}");
    // Support on the true edge reaches 2 px past its end (the disc).
    assert!((m.dont_care_length - 38.0).abs() < 1e-9, "{m:?}");
    assert!((m.detected_length - 102.0).abs() < 1e-9);
    assert_eq!(m.off_angle, 0.0);
}

#[test]
fn strong_recall_counts_only_edges_of_contrast_30_and_up() {
    let strong = with_contrast(seg(0.0, 0.0, 100.0, 0.0), 50.0);
    let weak = with_contrast(seg(0.0, 40.0, 100.0, 40.0), 15.0);
    let truth = vec![strong, weak];
    let m = tally(&[seg(0.0, 40.0, 100.0, 40.0)], &truth, &[]);
    assert!((m.recall - 0.5).abs() < 1e-9);
    assert_eq!(m.recall_strong, 0.0);
    assert!((m.strong_length - 100.0).abs() < 1e-12);
    let m = tally(&[seg(0.0, 0.0, 50.0, 0.0)], &truth, &[]);
    assert!((m.recall_strong - 0.5).abs() < 1e-9, "{m:?}");
}

#[test]
fn close_recall_covers_the_parts_with_a_parallel_edge_4_to_8_px_away() {
    // Two edges 6 px apart over x 0–100; the lower one runs on to x = 160
    // alone. A far edge has no neighbour.
    let truth = vec![
        seg(0.0, 0.0, 100.0, 0.0),
        seg(0.0, 6.0, 160.0, 6.0),
        seg(0.0, 80.0, 100.0, 80.0),
    ];
    // Finding the upper edge only: half the close length.
    let m = tally(&[seg(0.0, 0.0, 100.0, 0.0)], &truth, &[]);
    assert!((m.close_length - 200.0).abs() < 1e-9, "{m:?}");
    assert!((m.recall_close - 0.5).abs() < 1e-9, "{m:?}");
    // The lower edge's lone stretch is not close: finding it adds nothing.
    let m = tally(&[seg(100.0, 6.0, 160.0, 6.0)], &truth, &[]);
    assert_eq!(m.recall_close, 0.0);
    // 10 px apart is not close; a pair converging from 10 to 6 px is close
    // where it is within 8 px.
    let far = vec![seg(0.0, 0.0, 100.0, 0.0), seg(0.0, 10.0, 100.0, 10.0)];
    assert_eq!(tally(&[], &far, &[]).close_length, 0.0);
    let conv = vec![seg(0.0, 0.0, 100.0, 0.0), seg(0.0, 10.0, 100.0, 6.0)];
    let m = tally(&[], &conv, &[]);
    // On each edge about x 50–100 (distance 8 → 6).
    assert!((m.close_length - 2.0 * 50.0).abs() < 0.2, "{m:?}");
}

#[test]
fn tilted_and_bridging_lines_are_off_angle() {
    let truth = vec![seg(0.0, 0.0, 100.0, 0.0)];
    // 5° off, from the edge's start: within 2 px for 2 / sin 5° of its
    // 50 px, none of it supports.
    let t5 = 5f64.to_radians();
    let tilted = seg(0.0, 0.0, 50.0 * t5.cos(), 50.0 * t5.sin());
    let m = tally(&[tilted], &truth, &[]);
    assert_eq!(m.precision, 0.0);
    let expect = 2.0 / t5.sin() / 50.0;
    assert!((m.off_angle - expect).abs() < 1e-6, "{m:?} vs {expect}");
    // A segment bent across two edges 6 px apart (3.4° off both): all of it.
    let pair = vec![seg(0.0, 0.0, 100.0, 0.0), seg(0.0, 6.0, 100.0, 6.0)];
    let m = tally(&[seg(0.0, 0.0, 100.0, 6.0)], &pair, &[]);
    assert!((m.off_angle - 1.0).abs() < 1e-9, "{m:?}");
    // A good detection is not off-angle at all.
    let m = tally(&[seg(0.0, 0.3, 100.0, 0.3)], &truth, &[]);
    assert_eq!(m.off_angle, 0.0);
    // A line between two far-apart parallel edges is plain false, not off-angle.
    let far = vec![seg(0.0, 0.0, 100.0, 0.0), seg(0.0, 30.0, 100.0, 30.0)];
    let m = tally(&[seg(0.0, 15.0, 100.0, 15.0)], &far, &[]);
    assert_eq!(m.off_angle, 0.0);
}

#[test]
fn shared_endpoints_compare_two_detectors_on_the_edges_both_found() {
    let truth = vec![seg(0.0, 0.0, 100.0, 0.0), seg(0.0, 50.0, 100.0, 50.0)];
    // The first finds both edges (the second one 1 px off) in image 0, and
    // only the second edge in image 1; the other finds the first edge in
    // image 0 (0.3 px off) and the first edge in image 1.
    let (mut first, mut second) = (Tally::default(), Tally::default());
    first.add(
        &[seg(0.0, 0.1, 100.0, 0.1), seg(0.0, 51.0, 100.0, 51.0)],
        &truth,
    );
    first.add(&[seg(0.0, 50.2, 100.0, 50.2)], &truth);
    second.add(&[seg(0.0, 0.3, 100.0, 0.3)], &truth);
    second.add(&[seg(0.0, 0.4, 100.0, 0.4)], &truth);
    assert!((first.metrics().endpoint_mean - 0.1 / 3.0 - 1.2 / 3.0).abs() < 1e-9);
    let sh = shared_endpoints(&first, &second);
    assert_eq!(sh.edges, 1, "{sh:?}");
    assert_eq!((sh.first_segments, sh.second_segments), (1, 1));
    assert!((sh.first_mean - 0.1).abs() < 1e-9, "{sh:?}");
    assert!((sh.second_mean - 0.3).abs() < 1e-9, "{sh:?}");
    // Symmetric, and nothing shared with a detector that found nothing.
    let back = shared_endpoints(&second, &first);
    assert!((back.first_mean - 0.3).abs() < 1e-9 && (back.second_mean - 0.1).abs() < 1e-9);
    let none = shared_endpoints(&first, &Tally::default());
    assert_eq!((none.edges, none.first_segments), (0, 0));
    assert_eq!(none.first_mean, 0.0);
}
