//! Large generated maps: stand-ins, of the same sizes, for the public OctoMap maps the
//! planner must handle (a campus, an office hall), to measure setup, open-air hops and
//! long crossings on tens of millions of cells.
//!
//! | name | box (m) | default resolution | cells at the default | what is in it |
//! |---|---|---|---|---|
//! | `campus[:RES]` | 100 x 100 x 20 | 0.2 m | 25 million | a 5 x 5 grid of buildings 6-16 m high, 8 m streets, lamp posts |
//! | `hall[:RES]` | 60 x 40 x 10 | 0.1 m | 24 million | 18 rooms off a 2 m corridor, 1 m doors, 0.6 m windows between rooms |
//!
//! `RES` is the resolution in metres: 0.1 to 0.4 for the campus (0.1 gives the
//! 200-million-cell map), 0.05 to 0.2 for the hall (its 0.2 m walls need a voxel). Every voxel of the box is known, as
//! in the other scenarios. The start and goal make the long crossing (96 m across the
//! campus between its buildings; 54 m from a room at one end of the hall to a room at
//! the other); `--start` and `--goal` give other queries (the open-air hops of the
//! benchmarks are named in the scenario's description).

use std::f64::consts::FRAC_PI_2;

use super::scenarios::{along, fill, shell_box, Scenario};
use super::ProblemError;
use crate::map::grid::Cell;

/// Allowed resolutions of `campus:RES` (m).
pub const CAMPUS_RESOLUTIONS: std::ops::RangeInclusive<f64> = 0.1..=0.4;
/// Allowed resolutions of `hall:RES` (m).
pub const HALL_RESOLUTIONS: std::ops::RangeInclusive<f64> = 0.05..=0.2;

/// Builds `campus[:RES]` or `hall[:RES]`; `None` for any other name.
pub fn build(name: &str) -> Option<Result<Scenario, ProblemError>> {
    let (base, res) = match name.split_once(':') {
        Some((b, r)) => (b, Some(r)),
        None => (name, None),
    };
    let (default, range): (f64, _) = match base {
        "campus" => (0.2, CAMPUS_RESOLUTIONS),
        "hall" => (0.1, HALL_RESOLUTIONS),
        _ => return None,
    };
    let res = match res {
        None => default,
        Some(text) => match text.parse::<f64>() {
            Ok(v) if range.contains(&v) => v,
            Ok(v) => {
                return Some(Err(ProblemError::OutOfRange {
                    name: "resolution",
                    value: v,
                    lo: *range.start(),
                    hi: *range.end(),
                }))
            }
            Err(_) => {
                return Some(Err(ProblemError::NotANumber {
                    part: name.into(),
                    value: text.into(),
                }))
            }
        },
    };
    Some(Ok(if base == "campus" {
        campus(res)
    } else {
        hall(res)
    }))
}

/// Campus block pitch (m): a 12 m building and an 8 m street.
const BLOCK: f64 = 20.0;
/// Where the first building begins (m).
const FIRST: f64 = 4.0;
/// Building footprint (m).
const FOOTPRINT: f64 = 12.0;

/// A 100 x 100 x 20 m campus at `res`.
pub fn campus(res: f64) -> Scenario {
    let size = [100.0, 100.0, 20.0];
    let shell = res.max(0.2);
    let mut g = shell_box(size, res, shell);
    // Ground slab, 0.4 m.
    fill(
        &mut g,
        [0.0, 0.0, 0.0],
        [size[0], size[1], 0.4],
        Cell::Occupied,
    );
    for i in 0..5 {
        for j in 0..5 {
            let (x0, y0) = (FIRST + BLOCK * i as f64, FIRST + BLOCK * j as f64);
            let height = 6.0 + ((3 * i + 7 * j) % 11) as f64;
            fill(
                &mut g,
                [x0, y0, 0.0],
                [x0 + FOOTPRINT, y0 + FOOTPRINT, height],
                Cell::Occupied,
            );
            // A lamp post 1.5 m off the building's south-west corner, 0.4 m square.
            let (px, py) = (x0 - 1.5, y0 - 1.5);
            fill(
                &mut g,
                [px - 0.2, py - 0.2, 0.0],
                [px + 0.2, py + 0.2, 5.0],
                Cell::Occupied,
            );
        }
    }
    along(
        format!("campus:{res}"),
        "A 100 x 100 x 20 m campus: 25 buildings (12 m square, 6-16 m high) on a \
                      20 m grid, 8 m streets, lamp posts. The crossing flies 96 m along y = 50 \
                      through the building in its way, around it by the streets; an open-air hop \
                      is --start 40,20,10 --goal 45,20,10 (4 m from every building).",
        g,
        FRAC_PI_2,
        2.0,
        &[[2.0, 50.0], [2.0, 60.0], [98.0, 60.0], [98.0, 50.0]],
    )
}

/// Hall corridor: y from `CORRIDOR.0` to `CORRIDOR.1` (m), between two 0.2 m walls.
const CORRIDOR: (f64, f64) = (19.0, 21.0);
/// Room width along x (m).
const ROOM: f64 = 6.0;
/// Wall thickness (m).
const HALL_WALL: f64 = 0.2;
/// Door width and height (m).
const DOOR: (f64, f64) = (1.0, 2.2);
/// Window width and height (m) in every other partition wall, its sill (m).
const WINDOW: (f64, f64, f64) = (0.6, 0.6, 1.2);

/// A 60 x 40 x 10 m office hall at `res`.
pub fn hall(res: f64) -> Scenario {
    let size = [60.0, 40.0, 10.0];
    let shell = res.max(0.2);
    let mut g = shell_box(size, res, shell);
    let (c0, c1) = CORRIDOR;
    for (y0, y1) in [(c0 - HALL_WALL, c0), (c1, c1 + HALL_WALL)] {
        fill(
            &mut g,
            [0.0, y0, 0.0],
            [size[0], y1, size[2]],
            Cell::Occupied,
        );
    }
    for k in 0..10 {
        let x = ROOM * k as f64;
        // Partition walls between rooms (not at the ends: the shell is there).
        if k > 0 {
            for (y0, y1) in [(0.0, c0), (c1, size[1])] {
                fill(
                    &mut g,
                    [x, y0, 0.0],
                    [x + HALL_WALL, y1, size[2]],
                    Cell::Occupied,
                );
                if k % 2 == 0 {
                    let yc = (y0 + y1) / 2.0;
                    let (w, h, sill) = WINDOW;
                    fill(
                        &mut g,
                        [x, yc - w / 2.0, sill],
                        [x + HALL_WALL, yc + w / 2.0, sill + h],
                        Cell::Free,
                    );
                }
            }
        }
        // A door from each room into the corridor, in the middle of the room.
        let xc = x + ROOM / 2.0;
        let (w, h) = DOOR;
        for (y0, y1) in [(c0 - HALL_WALL, c0), (c1, c1 + HALL_WALL)] {
            fill(
                &mut g,
                [xc - w / 2.0, y0, 0.0],
                [xc + w / 2.0, y1, h],
                Cell::Free,
            );
        }
    }
    // The floor stays solid under the doors.
    fill(
        &mut g,
        [0.0, 0.0, 0.0],
        [size[0], size[1], shell],
        Cell::Occupied,
    );
    along(
        format!("hall:{res}"),
        "A 60 x 40 x 10 m office hall: a 2 m corridor with ten rooms (6 m x 19 m, \
                      full-height walls) on each side, a 1 m x 2.2 m door from each room, a \
                      0.6 m window in every other partition wall. The crossing flies from the \
                      first room on one side to the last on the other; a hop in the corridor is \
                      --start 20,20,1.3 --start-yaw-deg 0 --goal 25,20,1.3.",
        g,
        FRAC_PI_2,
        1.3,
        &[[3.0, 10.0], [3.0, 20.0], [57.0, 20.0], [57.0, 30.0]],
    )
}
