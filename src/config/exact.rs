//! Fixed-size arrays read exactly: a scenario array with more or fewer entries than
//! the quantity has (a velocity of three numbers, a rigid line of three points) is an
//! error naming its length, never truncated (serde's own arrays stop reading after
//! the length they want and drop the rest).

use serde::de::{Deserialize, Deserializer, Error};

/// Reads `[T; N]` from an array of exactly `N` entries.
pub fn array<'de, D, T, const N: usize>(d: D) -> Result<[T; N], D::Error>
where
    D: Deserializer<'de>,
    T: Deserialize<'de>,
{
    let v = Vec::<T>::deserialize(d)?;
    exactly(v)
}

/// A vector as a scenario gives it: two components (a plane model's, `z = 0`) or
/// three (a solid's); validation checks the count against the model's dimension.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Vector {
    /// `[x, y, z]`.
    pub xyz: [f64; 3],
    /// How many components the scenario gave (0: not given, the default).
    pub len: usize,
}

/// Reads a [`Vector`] of two or three components; any other length is an error
/// naming it.
pub fn vector<'de, D>(d: D) -> Result<Vector, D::Error>
where
    D: Deserializer<'de>,
{
    let v = Vec::<f64>::deserialize(d)?;
    match v.len() {
        2 => Ok(Vector {
            xyz: [v[0], v[1], 0.0],
            len: 2,
        }),
        3 => Ok(Vector {
            xyz: [v[0], v[1], v[2]],
            len: 3,
        }),
        n => Err(D::Error::custom(format!(
            "has {n} entries, expected 2 (a plane model) or 3 (a solid)"
        ))),
    }
}

/// Reads an optional [`vector`] (with `#[serde(default)]`).
pub fn option_vector<'de, D>(d: D) -> Result<Option<Vector>, D::Error>
where
    D: Deserializer<'de>,
{
    vector(d).map(Some)
}

/// Reads an optional `[T; N]` (with `#[serde(default)]`).
pub fn option_array<'de, D, T, const N: usize>(d: D) -> Result<Option<[T; N]>, D::Error>
where
    D: Deserializer<'de>,
    T: Deserialize<'de>,
{
    Vec::<T>::deserialize(d).and_then(exactly).map(Some)
}

/// Reads an optional segment `[[x, y], [x, y]]`: two points of two coordinates.
pub fn option_segment<'de, D>(d: D) -> Result<Option<[[f64; 2]; 2]>, D::Error>
where
    D: Deserializer<'de>,
{
    let points = Vec::<Vec<f64>>::deserialize(d)?;
    let points: Vec<[f64; 2]> = points
        .into_iter()
        .map(exactly)
        .collect::<Result<_, D::Error>>()?;
    exactly(points).map(Some)
}

fn exactly<E: Error, T, const N: usize>(v: Vec<T>) -> Result<[T; N], E> {
    let n = v.len();
    v.try_into().map_err(|_| {
        E::custom(format!(
            "has {n} entries, expected {N}{}",
            if N == 2 { " (x, y)" } else { "" }
        ))
    })
}
