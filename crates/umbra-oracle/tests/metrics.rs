//! Band counting, comparison metrics and the diff image on small hand-made masks.

use umbra_oracle::metrics::{BAND, FALSE_LIGHT, FALSE_SHADOW};
use umbra_oracle::{boundary_band, compare, diff_image, Metrics, OracleError, Reference, SampleClass};

use SampleClass::{Background as B, Lit as L, Shadowed as S};

/// 4x3 reference:
/// ```text
///   x: 0 1 2 3
///   y0 L L S S
///   y1 L L S S
///   y2 B B B B
/// ```
fn four_by_three() -> Reference {
    let class = vec![L, L, S, S, L, L, S, S, B, B, B, B];
    let band = boundary_band(4, 3, &class, &[false; 12]);
    Reference { width: 4, height: 3, class, band, parts: Vec::new() }
}

#[test]
fn band_is_where_the_3x3_neighbourhood_holds_both_classes() {
    let r = four_by_three();
    // Column 1 sees column 2 (S) and itself (L); column 2 sees column 1: band. Column 0 sees
    // columns 0-1 only (all L), column 3 columns 2-3 only (all S): not band. Row 2 is
    // background: never band. So band = (1,0), (2,0), (1,1), (2,1).
    #[rustfmt::skip]
    let expected = vec![
        false, true, true, false,
        false, true, true, false,
        false, false, false, false,
    ];
    assert_eq!(r.band, expected);
}

#[test]
fn background_neighbours_do_not_count_as_a_class() {
    // L B S in one row: pixel 0 sees {L, B}, pixel 2 sees {B, S}: one class each, no band,
    // although lit and shadowed are only two pixels apart.
    assert_eq!(boundary_band(3, 1, &[L, B, S], &[false; 3]), vec![false, false, false]);
    // L S B: pixels 0 and 1 see both classes; pixel 2 is background.
    assert_eq!(boundary_band(3, 1, &[L, S, B], &[false; 3]), vec![true, true, false]);
    // Diagonal neighbours count (3x3, not 4-neighbourhood): L at (0,0), S at (1,1).
    assert_eq!(boundary_band(2, 2, &[L, B, B, S], &[false; 4]), vec![true, false, false, true]);
    // A grazing sample is band on its own; a grazing flag on background is ignored.
    assert_eq!(boundary_band(3, 1, &[L, L, B], &[false, true, true]), vec![false, true, false]);
}

#[test]
fn compare_counts_on_a_hand_made_mask() {
    let r = four_by_three();
    // The method shadows everything, background included (ignored).
    let all = vec![true; 12];
    let m = compare(&r, &all).unwrap();
    // 8 samples (rows 0-1), 4 shadowed in the reference (columns 2-3). The method is wrong on
    // the 4 lit samples: (0,0), (1,0), (0,1), (1,1). Of those, column 1 is band (2 samples),
    // column 0 is not (2 samples). Band samples: 4 (see the band test).
    assert_eq!(
        m,
        Metrics {
            samples: 8,
            shadowed_reference: 4,
            mismatches: 4,
            band_samples: 4,
            band_mismatches: 2,
            mismatches_outside_band: 2
        }
    );
    // The method equal to the reference on samples, garbage on background: no mismatch at all.
    let exact: Vec<bool> = r.class.iter().map(|&c| c != L).collect();
    let m = compare(&r, &exact).unwrap();
    assert_eq!((m.mismatches, m.band_mismatches, m.mismatches_outside_band), (0, 0, 0));
    assert_eq!((m.samples, m.shadowed_reference, m.band_samples), (8, 4, 4));
    // Shadow boundary moved one pixel right (column 2 lit too): 2 false lights, both in band.
    let shifted = vec![false, false, false, true, false, false, false, true, false, false, false, false];
    let m = compare(&r, &shifted).unwrap();
    assert_eq!((m.mismatches, m.band_mismatches, m.mismatches_outside_band), (2, 2, 0));
}

#[test]
fn metrics_serialize_with_exactly_the_documented_keys() {
    let m = Metrics {
        samples: 1,
        shadowed_reference: 2,
        mismatches: 3,
        band_samples: 4,
        band_mismatches: 5,
        mismatches_outside_band: 6,
    };
    let v = serde_json::to_value(m).unwrap();
    let obj = v.as_object().unwrap();
    let mut keys: Vec<&str> = obj.keys().map(|k| k.as_str()).collect();
    keys.sort();
    assert_eq!(
        keys,
        ["band_mismatches", "band_samples", "mismatches", "mismatches_outside_band", "samples", "shadowed_reference"]
    );
    assert_eq!(obj["mismatches_outside_band"], 6);
}

#[test]
fn diff_image_colours() {
    let r = four_by_three();
    // (0,0): lit, not band, method shadowed -> false shadow, red.
    // (3,1): shadowed, not band, method lit -> false light, blue.
    // (1,0): band, method wrong -> grey; (2,1): band, method right -> grey.
    // (0,1): lit, method lit -> base dimmed. (0,2): background -> base dimmed.
    let method = vec![true, true, true, true, false, false, true, false, true, false, false, false];
    let base: Vec<u8> = (0..12).flat_map(|i| [200u8, 100, (i * 20) as u8, 7]).collect();
    let img = diff_image(&r, &method, &base).unwrap();
    assert_eq!(img.len(), 48);
    let px = |x: usize, y: usize| -> [u8; 4] { img[4 * (y * 4 + x)..4 * (y * 4 + x) + 4].try_into().unwrap() };
    assert_eq!(px(0, 0), FALSE_SHADOW);
    assert_eq!(px(3, 1), FALSE_LIGHT);
    assert_eq!(px(1, 0), BAND);
    assert_eq!(px(2, 1), BAND);
    // Dimmed: c * 102 / 256 (truncated), alpha opaque. Pixel (0,1) is index 4: blue = 80.
    assert_eq!(px(0, 1), [79, 39, 31, 255]);
    assert_eq!(px(0, 2), [79, 39, (160u16 * 102 / 256) as u8, 255]);
    // Matching shadowed sample outside the band: (3,0) is S, method true -> dimmed base.
    assert_eq!(px(3, 0), [79, 39, (60u16 * 102 / 256) as u8, 255]);
}

#[test]
fn size_mismatches_are_typed_errors() {
    let r = four_by_three();
    assert_eq!(
        compare(&r, &[false; 11]).unwrap_err(),
        OracleError::SizeMismatch { what: "method mask", expected: 12, actual: 11, width: 4, height: 3 }
    );
    assert!(matches!(
        diff_image(&r, &[false; 12], &[0u8; 47]),
        Err(OracleError::SizeMismatch { expected: 48, actual: 47, .. })
    ));
    let mut broken = r.clone();
    broken.band.pop();
    assert!(matches!(compare(&broken, &[false; 12]), Err(OracleError::SizeMismatch { what: "reference band", .. })));
}
