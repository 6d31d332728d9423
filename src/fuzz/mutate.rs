//! Mutations: geometric ones on a surface before it is written (extreme magnitudes, tiny and
//! huge bodies, near-coincident vertices, needle and cap triangles), byte ones on the file after
//! (bit flips, number substitutions, truncations, lines deleted or repeated). Each returns a
//! short description for the record of the run.

use crate::geometry::DVec3;
use crate::surface::family::SplitMix64;
use crate::surface::Surface;

/// Values that break naive arithmetic: overflow when squared or counted, underflow, the limits
/// of the accepted range and just beyond, the edges of `f32` and integer types.
pub const EXTREME_REALS: [f64; 16] = [
    1e19,
    -1e19,
    1e300,
    f64::MAX,
    -f64::MAX,
    f64::MIN_POSITIVE,
    5e-324,
    1e-300,
    1e12,
    -1.000001e12,
    3.4028235e38,
    1e-12,
    0.0,
    -0.0,
    4294967296.0,
    9.2e18,
];

const EXTREME_TOKENS: [&str; 18] = [
    "nan",
    "inf",
    "-inf",
    "1e19",
    "-1e308",
    "1e-320",
    "0",
    "-1",
    "4294967295",
    "4294967296",
    "18446744073709551615",
    "99999999999999999999",
    "2147483648",
    "1e999",
    "1e13",
    "-3e15",
    "1e-17",
    "1e12",
];

/// One of `items`, uniformly.
pub fn pick<'a, T>(rng: &mut SplitMix64, items: &'a [T]) -> &'a T {
    &items[rng.below(items.len())]
}

/// Change the shape: returns what was done.
pub fn geometric(s: &mut Surface, rng: &mut SplitMix64) -> String {
    let n = s.points.len();
    let decade =
        |rng: &mut SplitMix64, lo: i32, hi: i32| 10f64.powi(lo + rng.below((hi - lo + 1) as usize) as i32);
    match rng.below(7) {
        0 => {
            let k = decade(rng, -16, 16);
            s.points.iter_mut().for_each(|p| *p *= k);
            format!("scaled by {k:e}")
        }
        1 => {
            let shift = DVec3::new(rng.unit() - 0.5, rng.unit(), -rng.unit()) * decade(rng, 0, 20);
            s.points.iter_mut().for_each(|p| *p += shift);
            format!("moved by {shift}")
        }
        2 => {
            let (v, w) = (rng.below(n), rng.below(n));
            let eps = decade(rng, -17, -3);
            s.points[v] = s.points[w] + DVec3::splat(eps);
            format!("vertex {v} moved within {eps:e} of vertex {w}")
        }
        3 => {
            let [a, b, _] = s.triangles[rng.below(s.triangles.len())];
            let t = 1.0 - decade(rng, -16, -2);
            s.points[a as usize] = s.points[b as usize].lerp(s.points[a as usize], 1.0 - t);
            format!("needle: vertex {a} moved to {t} of the way to vertex {b}")
        }
        4 => {
            let [a, b, c] = s.triangles[rng.below(s.triangles.len())];
            let lift = decade(rng, -16, -2);
            let mid = 0.5 * (s.points[a as usize] + s.points[b as usize]);
            s.points[c as usize] = mid + lift * (s.points[c as usize] - mid);
            format!("cap: vertex {c} lowered to {lift:e} of its height over edge ({a}, {b})")
        }
        5 => {
            let (v, axis) = (rng.below(n), rng.below(3));
            let x = *pick(rng, &EXTREME_REALS);
            s.points[v][axis] = x;
            format!("vertex {v} coordinate {axis} set to {x:e}")
        }
        _ => {
            let eps = decade(rng, -15, -6);
            let mut jitter = || eps * (rng.unit() - 0.5);
            s.points
                .iter_mut()
                .for_each(|p| *p += DVec3::new(jitter(), jitter(), jitter()) * p.length().max(1.0));
            format!("jittered by {eps:e}")
        }
    }
}

/// Damage the bytes of a file: returns what was done.
pub fn bytes(data: &mut Vec<u8>, text: bool, rng: &mut SplitMix64) -> String {
    if data.is_empty() {
        data.push(rng.next_u64() as u8);
        return "one random byte".into();
    }
    let kinds = if text { 6 } else { 4 };
    match rng.below(kinds) {
        0 => {
            let flips = 1 + rng.below(8);
            for _ in 0..flips {
                let i = rng.below(data.len());
                data[i] ^= 1 << rng.below(8);
            }
            format!("{flips} bits flipped")
        }
        1 => {
            let at = rng.below(data.len() + 1);
            data.truncate(at);
            format!("truncated to {at} bytes")
        }
        2 => {
            let at = rng.below(data.len());
            let width = if rng.chance(0.5) { 4 } else { 8 };
            let value: Vec<u8> = match (width, rng.below(2)) {
                (4, 0) => {
                    (pick(rng, &[u32::MAX, 0x8000_0000, 0x7fff_ffff, 1 << 30, 0]).to_le_bytes()).to_vec()
                }
                (4, _) => (*pick(rng, &EXTREME_REALS) as f32).to_le_bytes().to_vec(),
                (_, 0) => pick(rng, &[u64::MAX, 1 << 40, 1 << 62]).to_le_bytes().to_vec(),
                _ => pick(rng, &EXTREME_REALS).to_le_bytes().to_vec(),
            };
            let end = (at + width).min(data.len());
            data[at..end].copy_from_slice(&value[..end - at]);
            format!("{width} bytes at {at} set to {value:02x?}")
        }
        3 => {
            let (at, len) = (rng.below(data.len()), 1 + rng.below(64));
            let chunk: Vec<u8> = data[at..(at + len).min(data.len())].to_vec();
            let to = rng.below(data.len() + 1);
            data.splice(to..to, chunk);
            format!("{len} bytes from {at} repeated at {to}")
        }
        4 => substitute_number(data, rng),
        _ => edit_line(data, rng),
    }
}

/// Replace one number of a text with an extreme token.
pub fn substitute_number(data: &mut Vec<u8>, rng: &mut SplitMix64) -> String {
    let starts: Vec<usize> = (0..data.len())
        .filter(|&i| {
            data[i].is_ascii_digit()
                && (i == 0 || !data[i - 1].is_ascii_alphanumeric() && data[i - 1] != b'.')
        })
        .collect();
    if starts.is_empty() {
        return "no number to replace".into();
    }
    let start = *pick(rng, &starts);
    let start = if start > 0 && data[start - 1] == b'-' { start - 1 } else { start };
    let end = (start + 1..data.len())
        .find(|&i| !(data[i].is_ascii_alphanumeric() || matches!(data[i], b'.' | b'+' | b'-')))
        .unwrap_or(data.len());
    let token = *pick(rng, &EXTREME_TOKENS);
    let old = String::from_utf8_lossy(&data[start..end]).into_owned();
    data.splice(start..end, token.bytes());
    format!("number {old:?} at byte {start} replaced by {token}")
}

/// Delete or repeat one line of a text.
fn edit_line(data: &mut Vec<u8>, rng: &mut SplitMix64) -> String {
    let starts: Vec<usize> =
        std::iter::once(0).chain((0..data.len()).filter(|&i| data[i] == b'\n').map(|i| i + 1)).collect();
    let k = rng.below(starts.len());
    let start = starts[k];
    let end = starts.get(k + 1).copied().unwrap_or(data.len());
    if rng.chance(0.5) {
        data.drain(start..end);
        format!("line {} deleted", k + 1)
    } else {
        let line = data[start..end].to_vec();
        data.splice(end..end, line);
        format!("line {} repeated", k + 1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mutations_are_deterministic_and_change_something() {
        let shape = crate::surface::shapes::cuboid(DVec3::ONE, 1);
        for seed in 0..50 {
            let run = || {
                let mut rng = SplitMix64::new(seed);
                let mut s = shape.clone();
                let what = geometric(&mut s, &mut rng);
                let mut data = super::super::seeds::write(&s, super::super::seeds::Encoding::Obj);
                let damage = bytes(&mut data, true, &mut rng);
                (what, damage, data)
            };
            assert_eq!(run(), run());
        }
    }
}
