//! One axis of a chart: its range from the data, its ticks and their labels.
//!
//! A plotters coordinate of its own, so that linear and log axes are one type (and
//! a figure may mix them) and so that the ticks (powers of ten on log axes, even
//! within one decade) and their labels are chosen here rather than by plotters.

use std::ops::Range;

use plotters::coord::ranged1d::{KeyPointHint, NoDefaultFormatting, Ranged, ValueFormatter};

use super::figure::Scale;

/// The number of labelled ticks an axis aims at (at most).
pub(crate) const TICKS: usize = 10;

/// The share of the data span added on each side.
const MARGIN: f64 = 0.04;

/// How tick values are written.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Format {
    /// Fixed point with this many decimals, trailing zeros trimmed.
    Fixed(usize),
    /// Scientific, `1.5e-4`, with the precision of ticks `10^exp` apart.
    Sci(i32),
    /// Multiples of powers of ten on a log axis: plain (`0.01`) or scientific (`1e-6`).
    Log { plain: bool },
}

/// An axis: scale, range (in data units) and ticks.
#[derive(Clone, Debug)]
pub(crate) struct Axis {
    scale: Scale,
    /// Range ends in data units (both positive on a log axis).
    lo: f64,
    hi: f64,
    /// Labelled ticks, ascending.
    ticks: Vec<f64>,
    /// Grid lines between the ticks (the ticks included), ascending.
    minor: Vec<f64>,
    format: Format,
}

impl Axis {
    /// The axis over `values`: their range plus a margin, from the finite values
    /// (the positive ones on a log axis); a placeholder range when there are none.
    pub(crate) fn from_values(scale: Scale, values: impl IntoIterator<Item = f64>) -> Axis {
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for v in values {
            if usable(scale, v) {
                lo = lo.min(v);
                hi = hi.max(v);
            }
        }
        match scale {
            Scale::Linear => Axis::linear(lo, hi),
            Scale::Log => Axis::log(lo, hi),
        }
    }

    fn linear(lo: f64, hi: f64) -> Axis {
        let (lo, hi) = if lo > hi {
            (0.0, 1.0)
        } else if hi - lo <= 1e-12 * hi.abs().max(lo.abs()) || hi - lo < f64::MIN_POSITIVE {
            // One value: a range around it.
            let d = if lo == 0.0 { 1.0 } else { 0.1 * lo.abs() };
            (lo - d, hi + d)
        } else {
            let d = MARGIN * (hi - lo);
            (lo - d, hi + d)
        };
        let (ticks, minor, step) = linear_ticks(lo, hi, TICKS);
        Axis {
            scale: Scale::Linear,
            lo,
            hi,
            ticks,
            minor,
            format: linear_format(lo, hi, step),
        }
    }

    fn log(lo: f64, hi: f64) -> Axis {
        let (mut a, mut b) = if lo > hi {
            (0.0, 1.0)
        } else {
            (lo.log10(), hi.log10())
        };
        if b - a < 1e-9 {
            a -= 0.5;
            b += 0.5;
        } else {
            let d = MARGIN * (b - a);
            a -= d;
            b += d;
        }
        let (lo, hi) = (10f64.powf(a), 10f64.powf(b));
        let (k0, k1) = ((a - 1e-9).floor() as i32, (b + 1e-9).ceil() as i32);
        let plain = k0 >= -3 && k1 <= 5;
        let in_range = |v: &f64| *v >= lo * (1.0 - 1e-12) && *v <= hi * (1.0 + 1e-12);
        let multiples = |ms: &[f64]| -> Vec<f64> {
            (k0..=k1)
                .flat_map(|k| ms.iter().map(move |m| m * 10f64.powi(k)))
                .filter(in_range)
                .collect()
        };
        let all: Vec<f64> = multiples(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]);
        let decades = multiples(&[1.0]);
        let (ticks, minor) = if decades.len() >= 3 {
            let stride = decades.len().div_ceil(TICKS);
            let ticks = (k0..=k1)
                .filter(|k| k.rem_euclid(stride as i32) == 0)
                .map(|k| 10f64.powi(k))
                .filter(in_range)
                .collect();
            let minor = if k1 - k0 <= 12 { all } else { decades };
            (ticks, minor)
        } else {
            let few = multiples(&[1.0, 2.0, 5.0]);
            if few.len() >= 3 {
                (few, all)
            } else if all.len() >= 2 {
                (all.clone(), all)
            } else {
                // Less than a factor of about two: linear ticks on the log axis.
                let (ticks, minor, step) = linear_ticks(lo, hi, TICKS);
                return Axis {
                    scale: Scale::Log,
                    lo,
                    hi,
                    ticks,
                    minor,
                    format: linear_format(lo, hi, step),
                };
            }
        };
        Axis {
            scale: Scale::Log,
            lo,
            hi,
            ticks,
            minor,
            format: Format::Log { plain },
        }
    }

    /// The labelled tick values.
    pub(crate) fn ticks(&self) -> &[f64] {
        &self.ticks
    }

    /// Where `v` falls on the axis: 0 at the low end, 1 at the high end.
    pub(crate) fn frac(&self, v: f64) -> f64 {
        let f = match self.scale {
            Scale::Linear => (v - self.lo) / (self.hi - self.lo),
            Scale::Log => {
                if v > 0.0 {
                    (v / self.lo).log10() / (self.hi / self.lo).log10()
                } else {
                    -1.0
                }
            }
        };
        if f.is_finite() {
            f.clamp(-1.0, 2.0)
        } else {
            -1.0
        }
    }

    /// The tick label of `v`.
    pub(crate) fn label(&self, v: f64) -> String {
        match self.format {
            Format::Fixed(decimals) => fixed(v, decimals),
            Format::Sci(step_exp) => {
                if v.abs() < 10f64.powi(step_exp) * 1e-6 {
                    return "0".into();
                }
                let e = v.abs().log10().floor() as i32;
                sci(v, (e - step_exp).max(0) as usize)
            }
            Format::Log { plain } => {
                let k = (v.log10() + 1e-9).floor() as i32;
                if plain {
                    fixed(v, (-k).max(0) as usize)
                } else {
                    sci(v, 0)
                }
            }
        }
    }
}

/// Whether `v` can be drawn on an axis of scale `scale`.
pub(crate) fn usable(scale: Scale, v: f64) -> bool {
    v.is_finite() && (scale == Scale::Linear || v > 0.0)
}

/// How the ticks `step` apart on a linear axis over `[lo, hi]` are written:
/// scientific for large or small magnitudes, fixed point otherwise.
fn linear_format(lo: f64, hi: f64, step: f64) -> Format {
    let step_exp = (step.log10() + 1e-9).floor() as i32;
    let big = lo.abs().max(hi.abs());
    if (1e-3..1e5).contains(&big) {
        Format::Fixed((-step_exp).max(0) as usize)
    } else {
        Format::Sci(step_exp)
    }
}

/// Ticks `1, 2 or 5 × 10^k` apart covering `[lo, hi]`, at most `n` of them (and at
/// least two for any positive span), the minor grid between them and the step.
fn linear_ticks(lo: f64, hi: f64, n: usize) -> (Vec<f64>, Vec<f64>, f64) {
    let raw = (hi - lo) / (n.max(3) - 1) as f64;
    if !(raw.is_finite() && raw > 0.0) {
        return (
            vec![lo, hi],
            vec![lo, hi],
            (hi - lo).abs().max(f64::MIN_POSITIVE),
        );
    }
    let base = 10f64.powf(raw.log10().floor());
    let (step, parts) = [(1.0, 5), (2.0, 4), (5.0, 5), (10.0, 5)]
        .into_iter()
        .map(|(m, parts)| (m * base, parts))
        .find(|(s, _)| *s >= raw * (1.0 - 1e-9))
        .unwrap_or((10.0 * base, 5));
    let grid = |step: f64| -> Vec<f64> {
        let first = (lo / step - 1e-9).ceil();
        let mut out = Vec::new();
        // Bounded: never more than a few hundred lines.
        for i in 0..500 {
            let v = (first + i as f64) * step;
            if v > hi + step * 1e-9 {
                break;
            }
            out.push(if v.abs() < step * 1e-9 { 0.0 } else { v });
        }
        out
    };
    (grid(step), grid(step / parts as f64), step)
}

/// `v` with `decimals` decimals, trailing zeros trimmed, never `-0`.
fn fixed(v: f64, decimals: usize) -> String {
    let s = format!("{v:.decimals$}");
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    };
    if s == "-0" {
        "0".into()
    } else {
        s
    }
}

/// `v` in scientific notation with `decimals` mantissa decimals, trimmed: `1.5e-4`.
fn sci(v: f64, decimals: usize) -> String {
    let s = format!("{v:.decimals$e}");
    match s.split_once('e') {
        Some((m, e)) if m.contains('.') => {
            format!("{}e{e}", m.trim_end_matches('0').trim_end_matches('.'))
        }
        _ => s,
    }
}

impl Ranged for Axis {
    type FormatOption = NoDefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        let f = self.frac(*value);
        (f64::from(limit.0) + f * f64::from(limit.1 - limit.0)).round() as i32
    }

    fn key_points<Hint: KeyPointHint>(&self, hint: Hint) -> Vec<f64> {
        let max = hint.max_num_points();
        if hint.weight().allow_light_points() && self.minor.len() <= max {
            return self.minor.clone();
        }
        if self.ticks.len() <= max {
            return self.ticks.clone();
        }
        let stride = self.ticks.len().div_ceil(max.max(1));
        self.ticks.iter().copied().step_by(stride).collect()
    }

    fn range(&self) -> Range<f64> {
        self.lo..self.hi
    }
}

impl ValueFormatter<f64> for Axis {
    fn format(value: &f64) -> String {
        format!("{value}")
    }

    fn format_ext(&self, value: &f64) -> String {
        self.label(*value)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn labels(a: &Axis) -> Vec<String> {
        a.ticks().iter().map(|v| a.label(*v)).collect()
    }

    #[test]
    fn linear_ticks_are_round_and_trimmed() {
        let a = Axis::from_values(Scale::Linear, [0.0, 20.0]);
        assert!(a.lo < 0.0 && a.hi > 20.0);
        assert_eq!(labels(&a), ["0", "5", "10", "15", "20"]);
        let a = Axis::from_values(Scale::Linear, [-0.3, 0.31]);
        assert_eq!(
            labels(&a),
            ["-0.3", "-0.2", "-0.1", "0", "0.1", "0.2", "0.3"]
        );
        let a = Axis::from_values(Scale::Linear, [0.0, 4e-5]);
        assert_eq!(
            labels(&a),
            ["0", "5e-6", "1e-5", "1.5e-5", "2e-5", "2.5e-5", "3e-5", "3.5e-5", "4e-5"]
        );
        assert!(a.ticks().len() <= TICKS);
    }

    #[test]
    fn log_ticks_are_powers_of_ten() {
        let a = Axis::from_values(Scale::Log, [1e-6, 0.0, -1.0, f64::NAN, 1e-2]);
        assert_eq!(labels(&a), ["1e-6", "1e-5", "1e-4", "1e-3", "1e-2"]);
        let a = Axis::from_values(Scale::Log, [0.01, 10.0]);
        assert_eq!(labels(&a), ["0.01", "0.1", "1", "10"]);
        // Within one decade: 1-2-5 or all multiples.
        let a = Axis::from_values(Scale::Log, [0.0031, 0.0089]);
        assert!(a.ticks().len() >= 2, "{:?}", a.ticks());
        assert_eq!(labels(&a)[0], "0.003");
        // A factor of 1.1: linear ticks.
        let a = Axis::from_values(Scale::Log, [100.0, 110.0]);
        assert_eq!(labels(&a), ["100", "102", "104", "106", "108", "110"]);
    }

    #[test]
    fn degenerate_ranges_get_placeholders() {
        for scale in [Scale::Linear, Scale::Log] {
            for vals in [vec![], vec![f64::NAN], vec![3.0], vec![0.0]] {
                let a = Axis::from_values(scale, vals.clone());
                assert!(
                    a.lo < a.hi && a.lo.is_finite() && a.hi.is_finite(),
                    "{vals:?}"
                );
                assert!(!a.ticks().is_empty(), "{scale:?} {vals:?}");
            }
        }
    }
}
