//! One line of a pass redone only where its output may change.
//!
//! A pass maps a line's inputs `f` to `D(q) = min_p (q - p)^2 + f(p)` (with the two
//! walls as sites of value 0 just outside the line when unknown space is occupied).
//! When the inputs change only at positions in `a..=b`, the output at `q` at distance
//! `k` from `a..=b` cannot change if `k^2 > D_old(q)`: then `D_old(q)` comes from an
//! unchanged site (every changed one is at least `k^2` away), which still gives it,
//! and no new value of a changed site comes below `k^2`. And `sqrt(D)` grows by at most
//! 1 per cell (the nearest site of `q` is one cell further from `q + 1`), so once
//! `k^2 > D_old(q)`, every cell further out fails too: the cells that may change form
//! one window around `a..=b`, found by walking out until the test fails.

use super::super::super::edt::{Scratch, NONE};

/// Largest finite value a pass stores (`edt_1d` clamps to it).
const FINITE_MAX: u64 = NONE as u64 - 1;

/// The cells `lo..=hi` of a line of `n` cells, whose inputs changed at positions in
/// `a..=b` only and whose output was `old`, outside which the output cannot change.
pub(super) fn window(n: usize, a: usize, b: usize, old: impl Fn(usize) -> u32) -> (usize, usize) {
    // NONE (no site at all) is infinitely far: everything may change.
    let may_change = |q: usize, k: usize| {
        let o = old(q);
        o == NONE || (k as u64) * (k as u64) <= o as u64
    };
    let mut hi = b;
    while hi + 1 < n && may_change(hi + 1, hi + 1 - b) {
        hi += 1;
    }
    let mut lo = a;
    while lo > 0 && may_change(lo - 1, a - (lo - 1)) {
        lo -= 1;
    }
    (lo, hi)
}

/// The x pass of one row, whose inputs are sites (0) or nothing (`NONE`): the squared
/// distance to the nearest site, by one sweep each way (the same numbers as the
/// transform, which is exact, in `O(n)` with no division).
pub(super) fn row_pass(sites: &[u32], walls: bool, out: &mut [u32]) {
    let n = sites.len();
    // Distance to the nearest site on the left, then on the right (None: no site).
    let mut last: Option<usize> = walls.then_some(0);
    for (x, o) in out.iter_mut().enumerate() {
        if sites[x] != NONE {
            last = Some(x + 1);
        }
        // `last` counts positions from -1, so the gap is x + 1 - last.
        *o = last.map_or(NONE, |l| square(x + 1 - l));
    }
    let mut next: Option<usize> = walls.then_some(n);
    for x in (0..n).rev() {
        if sites[x] != NONE {
            next = Some(x);
        }
        if let Some(r) = next {
            let v = square(r - x);
            if out[x] == NONE || v < out[x] {
                out[x] = v;
            }
        }
    }
}

/// `d^2` as a pass stores it.
fn square(d: usize) -> u32 {
    ((d as u64) * (d as u64)).min(FINITE_MAX) as u32
}

/// The pass's output at `q` of a line of `n` cells with inputs `f`: the nearest sites
/// first, stopping once the distance alone reaches the best value. The same number as
/// the line's Felzenszwalb-Huttenlocher transform, which is exact.
pub(super) fn value_at(n: usize, walls: bool, q: usize, f: impl Fn(usize) -> u32) -> u32 {
    let mut best = u64::MAX;
    if walls {
        let (left, right) = ((q + 1) as u64, (n - q) as u64);
        best = (left * left).min(right * right);
    }
    for k in 0..n {
        let k2 = (k as u64) * (k as u64);
        if k2 >= best || (k > q && q + k >= n) {
            break;
        }
        let mut take = |p: usize| {
            let v = f(p);
            if v != NONE {
                best = best.min(k2 + v as u64);
            }
        };
        if k <= q {
            take(q - k);
        }
        if k > 0 && q + k < n {
            take(q + k);
        }
    }
    if best == u64::MAX {
        NONE
    } else {
        best.min(FINITE_MAX) as u32
    }
}

/// The transform of a line of `n` cells with inputs `f` on its cells `lo..=hi`, into
/// `s.out` from index `lo - start`, where `start` is what it returns. Only the part of
/// the line within `reach` cells of the window is transformed where that provably gives
/// the whole line's values: a site left out lies at least `k` cells from window cell
/// `q` (`k` > `reach`), so it cannot lower a value of at most `k^2` (a tie gives the
/// same value). The reach is first the root of `old_max`, the window's largest value
/// before the change. Where a value found exceeds what its cell's `k` allows, the
/// reach becomes the root of the largest value found, which then holds for certain
/// (more sites only lower the values, and every `k` now exceeds the reach); a line
/// without a site, or a part that would reach both ends, takes the whole. Over a
/// passage run at 0.05 m (y columns of 200 cells) the part averaged 92 cells; the
/// first reach held for all but 0.1 % of the windows, and 2.7 % took the whole line.
pub(super) fn window_transform(
    s: &mut Scratch,
    n: usize,
    walls: bool,
    (lo, hi): (usize, usize),
    old_max: u32,
    f: impl Fn(usize) -> u32,
) -> usize {
    // Transforms cells `start..=end` into `s.out[..]`; the whole line is `0..=n - 1`.
    let transform = |s: &mut Scratch, start: usize, end: usize| {
        for p in start..=end {
            s.row[p - start] = f(p);
        }
        s.run_part(
            end + 1 - start,
            [walls && start == 0, walls && end == n - 1],
        );
    };
    let mut want = old_max;
    for _ in 0..2 {
        if want == NONE {
            break;
        }
        let reach = (want as f64).sqrt().ceil() as usize;
        let (start, end) = (
            lo.saturating_sub(reach),
            hi.saturating_add(reach).min(n - 1),
        );
        if start == 0 && end == n - 1 {
            break;
        }
        transform(s, start, end);
        // The nearest cell left out of the part, either way (none: the line's end).
        let left_out = |q: usize| {
            let before = (start > 0).then(|| q + 1 - start);
            let after = (end + 1 < n).then(|| end + 1 - q);
            before
                .into_iter()
                .chain(after)
                .min()
                .map_or(u64::MAX, |k| (k * k) as u64)
        };
        let values = &s.out[..end + 1 - start];
        if (lo..=hi).all(|q| values[q - start] as u64 <= left_out(q)) {
            return start;
        }
        want = (lo..=hi).map(|q| values[q - start]).max().unwrap_or(NONE);
    }
    transform(s, 0, n - 1);
    0
}

#[cfg(test)]
mod tests {
    use super::super::super::super::edt::Scratch;
    use super::*;
    use proptest::prelude::*;

    /// The Felzenszwalb-Huttenlocher transform of `f`.
    fn fh(f: &[u32], walls: bool) -> Vec<u32> {
        let mut s = Scratch::new(f.len());
        s.row[..f.len()].copy_from_slice(f);
        s.run(f.len(), walls);
        s.out[..f.len()].to_vec()
    }

    /// Inputs as a pass sees them: sites (0), partial squared distances, nothing.
    fn input(v: u8) -> u32 {
        match v % 4 {
            0 => 0,
            1 => NONE,
            _ => (v / 4) as u32,
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(512))]

        /// The sweep equals the transform on rows of sites.
        #[test]
        fn row_pass_matches_the_transform(
            row in proptest::collection::vec(any::<bool>(), 1..40),
            walls in any::<bool>(),
        ) {
            let sites: Vec<u32> = row.iter().map(|&o| if o { 0 } else { NONE }).collect();
            let mut out = vec![0; sites.len()];
            row_pass(&sites, walls, &mut out);
            prop_assert_eq!(out, fh(&sites, walls));
        }

        /// Every value equals the transform's, and every cell whose output changes
        /// lies in the window.
        #[test]
        fn window_holds_every_change_and_values_match(
            old in proptest::collection::vec(any::<u8>(), 1..40),
            changes in proptest::collection::vec((any::<u8>(), any::<u8>()), 1..4),
            spread in 0usize..6,
            walls in any::<bool>(),
        ) {
            let n = old.len();
            let f_old: Vec<u32> = old.iter().map(|&v| input(v)).collect();
            let mut f_new = f_old.clone();
            let a = changes[0].0 as usize % n;
            let mut b = a;
            for &(p, v) in &changes {
                let p = (a + p as usize % (spread + 1)).min(n - 1);
                f_new[p] = input(v);
                b = b.max(p);
            }
            let (d_old, d_new) = (fh(&f_old, walls), fh(&f_new, walls));
            let (lo, hi) = window(n, a, b, |q| d_old[q]);
            for q in 0..n {
                prop_assert_eq!(value_at(n, walls, q, |p| f_new[p]), d_new[q], "q {}", q);
                if d_old[q] != d_new[q] {
                    prop_assert!(lo <= q && q <= hi, "q {} changed outside {}..={}", q, lo, hi);
                }
            }
        }

        /// The transform of part of a line gives the whole line's values on the
        /// window, whatever the reach it starts from: too short (a value found then
        /// proves too little), long enough, or none (`NONE`).
        #[test]
        fn a_window_transformed_in_part_matches_the_whole_line(
            line in proptest::collection::vec(any::<u8>(), 1..120),
            ends in (any::<u8>(), any::<u8>()),
            old_max in prop_oneof![0u32..40, Just(NONE)],
            walls in any::<bool>(),
        ) {
            let n = line.len();
            // Mostly long gaps between sites, as in a room.
            let f: Vec<u32> = line
                .iter()
                .map(|&v| if v % 16 == 0 { input(v / 16) } else { NONE })
                .collect();
            let (a, b) = (ends.0 as usize % n, ends.1 as usize % n);
            let (lo, hi) = (a.min(b), a.max(b));
            let whole = fh(&f, walls);
            let mut s = Scratch::new(n);
            let start = window_transform(&mut s, n, walls, (lo, hi), old_max, |p| f[p]);
            prop_assert!(start <= lo);
            let part = &s.out[lo - start..=hi - start];
            prop_assert_eq!(part, &whole[lo..=hi], "window {}..={} from {}", lo, hi, start);
        }
    }
}
