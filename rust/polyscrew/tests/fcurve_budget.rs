//! The F-curve evaluation's memory footprint counts everything it allocates: the keys, the
//! Bezier segments prepared between them, the curves, the times rounded to `float32` and the
//! values. Its own binary: the memory budget is process-wide, and this is the only test here.

use std::mem::size_of;

use polyscrew::fcurve::bezier::BezierSegment;
use polyscrew::fcurve::{
    batch_footprint, evaluate_packed, Extrapolation, Key, PackedCurves, MAX_KEYS,
};
use polyscrew::Error;

#[test]
fn a_batch_over_the_budget_by_its_bezier_segments_is_refused() {
    // One BEZIER curve of K keys at T times.
    const K: usize = 1000;
    const T: usize = 1000;
    let co: Vec<f64> = (0..K).flat_map(|i| [i as f64, (i % 7) as f64]).collect();
    let left: Vec<f64> = co
        .iter()
        .enumerate()
        .map(|(j, v)| v - 0.3 * ((j + 1) % 2) as f64)
        .collect();
    let right: Vec<f64> = co
        .iter()
        .enumerate()
        .map(|(j, v)| v + 0.3 * ((j + 1) % 2) as f64)
        .collect();
    let (ones, zeros) = (vec![1.0; K], vec![0.0; K]);
    let packed = PackedCurves {
        offsets: &[0, K as i64],
        co: &co,
        handle_left: &left,
        handle_right: &right,
        interpolation: &[2; K], // BEZIER
        easing: &[0; K],
        back: &ones,
        amplitude: &ones,
        period: &zeros,
        extrapolation: &[Extrapolation::Constant],
        cycles: &[],
    };
    let times: Vec<f64> = (0..T).map(|i| i as f64 * 0.999).collect();
    // What the check counted before: the keys and the values only.
    let keys_and_values = K * size_of::<Key>() + T * size_of::<f64>();
    const { assert!(K <= MAX_KEYS) };

    let old = polyscrew::set_memory_budget(keys_and_values);
    let refused = evaluate_packed(&packed, &times);
    // The bytes the refusal names are enough: the same batch fits in them.
    let needed = match &refused {
        Err(Error::Memory { bytes, .. }) => *bytes,
        _ => 0,
    };
    polyscrew::set_memory_budget(needed);
    let fits = evaluate_packed(&packed, &times);
    polyscrew::set_memory_budget(old);

    match refused {
        Err(Error::Memory {
            bytes,
            budget: Some(budget),
            ..
        }) => {
            assert_eq!(budget, keys_and_values);
            assert_eq!(bytes, batch_footprint(1, K, T).get());
            // the Bezier segments, one per key at most
            assert!(bytes >= keys_and_values + (K - 1) * size_of::<Option<BezierSegment>>());
        }
        other => panic!(
            "{keys_and_values} bytes of budget: {:?}",
            other.map(|v| v.len())
        ),
    }
    let values = fits.expect("the same batch within the bytes it asked for");
    assert_eq!(values.len(), T);
    assert!(values.iter().all(|v| v.is_finite()));
}
