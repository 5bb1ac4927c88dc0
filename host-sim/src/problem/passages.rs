//! A parametric family of hard cases: tight, oblique openings.
//!
//! `passage:KEY=VALUE,...` builds a room (at 0.05 m by default) split by a wall with
//! a square window, approached obliquely and off centre, optionally followed by a
//! second wall with a door:
//!
//! | key | default | meaning |
//! |---|---|---|
//! | `w` | 0.5 | window width and height (m), 0.4 to 1.0, widened to whole voxels |
//! | `angle` | 45 | approach angle off the wall's normal (degrees), -60 to 60 |
//! | `offset` | 0 | window centre off the room's axis (m), -0.4 to 0.4 |
//! | `wall` | 0.2 | wall thickness (m), 0.1 to 2.0: from 0.5 m on, the window is a square tunnel |
//! | `door` | none | width (m) of a door in a second wall 2.5 m behind the first, 0.4 to 1.0 |
//! | `door_offset` | 0 | door centre off the room's axis (m), -3 to 3: from 1 m on, the head turns to the side right behind the window |
//! | `gap` | 2.5 | distance between the first wall and the second (m), 1 to 3 |
//! | `res` | 0.05 | map resolution (m), 0.025 to 0.1 |
//! | `sealed` | 0 | 1: the window is walled up (no way through; for failure reports) |
//! | `slit` | none | width (m) of slits that replace the window, 0.05 to 0.3, widened to whole voxels: vertical, 1.5 m tall, [`SLIT_PITCH`] apart, centred on the window's place |
//! | `slits` | 3 | how many slits, 1 to 5 (with `slit`) |
//!
//! Slits narrower than a unit (`slit` below `2 r_u`) leave a way through for a point
//! but none for the chain: they are the stand-ins for the gaps of real scans that
//! `arc plan` must refuse, quickly.
//!
//! Every instance carries a hand-made centre line ([`Scenario::route`]): straight in
//! along the approach, a turn 1 m before the wall onto its normal, straight through the
//! window's centre (and on through the door). `crate::witness::witness` lays the chain along it,
//! follow-the-leader fashion, and the exact verifier checks the result: an instance
//! with a witness is solvable, whatever the planner does.

use super::scenarios::fill;
use super::spec::{
    self, key_values, whole, within, Key,
    Values::{Flag, Real},
};
use super::ProblemError;
use crate::map::grid::{Cell, Grid};
use crate::problem::scenarios::Scenario;

/// Parameters of one instance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PassageSpec {
    /// Window width and height (m).
    pub w: f64,
    /// Approach angle off the wall's normal (degrees).
    pub angle_deg: f64,
    /// Window centre off the room's axis (m).
    pub offset: f64,
    /// Wall thickness (m).
    pub wall: f64,
    /// Door in a second wall: width (m) and offset (m).
    pub door: Option<(f64, f64)>,
    /// Distance between the first wall's far face and the second wall (m).
    pub gap: f64,
    /// Map resolution (m).
    pub res: f64,
    /// The window is walled up: start and goal in separate free regions.
    pub sealed: bool,
    /// Slits in place of the window: their width (m) and count.
    pub slits: Option<(f64, u32)>,
}

impl Default for PassageSpec {
    fn default() -> Self {
        Self {
            w: 0.5,
            angle_deg: 45.0,
            offset: 0.0,
            wall: 0.2,
            door: None,
            gap: WALL_GAP,
            res: 0.05,
            sealed: false,
            slits: None,
        }
    }
}

/// Room width (y) and height (z), m.
const ROOM_Y: f64 = 10.0;
const ROOM_Z: f64 = 2.6;
/// Outer shell thickness (m).
const SHELL: f64 = 0.2;
/// Where the first wall begins (x, m).
const WALL_X: f64 = 6.0;
/// Gap between the first wall and the second (m), unless `gap` is given.
const WALL_GAP: f64 = 2.5;
/// Height of the window's centre (m): half way up the room.
const Z_C: f64 = ROOM_Z / 2.0;
/// Distance between neighbouring slits' centres (m).
pub const SLIT_PITCH: f64 = 0.6;
/// Height of a slit (m).
const SLIT_HEIGHT: f64 = 1.5;

impl PassageSpec {
    /// The keys of `passage:` that stand for a field each, in the order their ranges
    /// are checked; `door`, `door_offset`, `slit` and `slits` are read in pairs by
    /// [`Self::parse`].
    const KEYS: &'static [Key<Self>] = &[
        Key::new("w", Real(0.4, 1.0), |s| &mut s.w),
        Key::new("angle", Real(-60.0, 60.0), |s| &mut s.angle_deg),
        Key::new("offset", Real(-0.4, 0.4), |s| &mut s.offset),
        Key::new("wall", Real(0.1, 2.0), |s| &mut s.wall),
        Key::new("res", Real(0.025, 0.1), |s| &mut s.res),
        Key::new("gap", Real(1.0, 3.0), |s| &mut s.gap),
        Key::new("sealed", Flag, |s| &mut s.sealed),
    ];

    /// Parses `KEY=VALUE,...` (see the module docs).
    pub fn parse(text: &str) -> Result<Self, ProblemError> {
        let mut s = Self::default();
        let mut door_offset = 0.0;
        let mut door = None;
        let (mut slit, mut slits) = (None, 3.0);
        for (k, v) in key_values(text)? {
            match k.as_str() {
                "door" => door = Some(v),
                "door_offset" => door_offset = v,
                "slit" => slit = Some(v),
                "slits" => slits = v,
                _ => spec::apply(Self::KEYS, &mut s, k, v)?,
            }
        }
        s.door = door.map(|d| (d, door_offset));
        if let Some(w) = slit {
            s.slits = Some((w, whole("slits", slits, 1.0, 5.0)? as u32));
        }
        s.check()?;
        Ok(s)
    }

    /// Checks the ranges of the module docs.
    pub fn check(&self) -> Result<(), ProblemError> {
        spec::check(self, Self::KEYS)?;
        if let Some((d, o)) = self.door {
            within("door", d, 0.4, 1.0)?;
            within("door_offset", o, -3.0, 3.0)?;
        }
        if let Some((w, k)) = self.slits {
            within("slit", w, 0.05, 0.3)?;
            within("slits", k as f64, 1.0, 5.0)?;
        }
        Ok(())
    }

    /// The name that builds this instance.
    pub fn name(&self) -> String {
        let mut n = format!(
            "passage:w={},angle={},offset={},wall={}",
            self.w, self.angle_deg, self.offset, self.wall
        );
        if let Some((d, o)) = self.door {
            n += &format!(",door={d},door_offset={o}");
            if self.gap != WALL_GAP {
                n += &format!(",gap={}", self.gap);
            }
        }
        if self.res != 0.05 {
            n += &format!(",res={}", self.res);
        }
        if self.sealed {
            n += ",sealed=1";
        }
        if let Some((w, k)) = self.slits {
            n += &format!(",slit={w},slits={k}");
        }
        n
    }

    /// A random instance of the family (widths 0.45-0.6 m, walls 0.1-0.3 m, angles
    /// up to 60 degrees either way, offsets up to 0.3 m, a door half of the time; one
    /// in five a tunnel instead, 0.5-0.6 m square and 0.6-1.5 m long), rounded to the
    /// centimetre and degree so that names stay short.
    pub fn random(rng: &mut impl rand::Rng) -> Self {
        let cm = |v: f64| (v * 100.0).round() / 100.0;
        let door = rng
            .gen_bool(0.5)
            .then(|| (cm(rng.gen_range(0.5..=0.8)), cm(rng.gen_range(-0.3..=0.3))));
        let tunnel = rng.gen_bool(0.2);
        let (w, wall) = if tunnel {
            (rng.gen_range(0.5..=0.6), rng.gen_range(0.6..=1.5))
        } else {
            (rng.gen_range(0.45..=0.6), rng.gen_range(0.1..=0.3))
        };
        Self {
            w: cm(w),
            angle_deg: rng.gen_range(-60.0f64..=60.0).round(),
            offset: cm(rng.gen_range(-0.3..=0.3)),
            wall: cm(wall),
            door,
            gap: WALL_GAP,
            res: 0.05,
            sealed: false,
            slits: None,
        }
    }

    /// A random instance of an opening, then a turn: a window (0.45-0.6 m, walls
    /// 0.1-0.3 m, 0-45 degrees off its normal either way), then a door (0.6-0.9 m)
    /// in a second wall 1-3 m on and 1-3 m to either side, so that the head turns
    /// while the tail is still in the window; rounded as [`Self::random`] rounds.
    pub fn random_turn(rng: &mut impl rand::Rng) -> Self {
        let cm = |v: f64| (v * 100.0).round() / 100.0;
        let angle_sign = if rng.gen_bool(0.5) { 1.0 } else { -1.0 };
        let angle = angle_sign * rng.gen_range(0.0f64..=45.0).round();
        let side_sign = if rng.gen_bool(0.5) { 1.0 } else { -1.0 };
        let side = side_sign * rng.gen_range(1.0..=3.0);
        Self {
            w: cm(rng.gen_range(0.45..=0.6)),
            angle_deg: angle,
            offset: 0.0,
            wall: cm(rng.gen_range(0.1..=0.3)),
            door: Some((cm(rng.gen_range(0.6..=0.9)), cm(side))),
            gap: cm(rng.gen_range(1.0..=3.0)),
            res: 0.05,
            sealed: false,
            slits: None,
        }
    }

    /// Where the walls and their openings lie, on the map's lattice.
    fn layout(&self) -> Layout {
        let r = self.res;
        let snap = |v: f64| (v / r).round() * r;
        // Openings: faces on the lattice, outward (at least as wide as asked).
        let down = |v: f64| (v / r + 1e-6).floor() * r;
        let up = |v: f64| (v / r - 1e-6).ceil() * r;
        let t = snap(self.wall).max(2.0 * r);
        let yc = ROOM_Y / 2.0 + self.offset;
        let hw = self.w / 2.0;
        let door = self.door.map(|(dw, doff)| Door {
            x: WALL_X + t + self.gap,
            y: (
                down(ROOM_Y / 2.0 + doff - dw / 2.0),
                up(ROOM_Y / 2.0 + doff + dw / 2.0),
            ),
        });
        let sx = snap(match door {
            Some(d) => d.x + 0.2 + 3.0,
            None => WALL_X + t + 3.5,
        });
        Layout {
            dims: [sx, ROOM_Y, ROOM_Z].map(|v| (v / r).round() as usize),
            t,
            window_y: (down(yc - hw), up(yc + hw)),
            window_z: (down(Z_C - hw), up(Z_C + hw)),
            door,
            slits: self.slits,
        }
    }

    /// The scenario.
    pub fn build(&self) -> Result<Scenario, ProblemError> {
        self.check()?;
        let r = self.res;
        let lay = self.layout();
        let mut g = Grid::new(r, [0; 3], lay.dims, Cell::Occupied, true)?;
        let size = lay.size(r);
        fill(
            &mut g,
            [SHELL; 3],
            [size[0] - SHELL, size[1] - SHELL, size[2] - SHELL],
            Cell::Free,
        );
        lay.first_wall(&mut g, self.sealed);
        // The route goes through the centre of the openings as built.
        let (yc, zc) = lay.window_centre();
        let mut goal = [WALL_X + lay.t + 1.5, yc, zc];
        let a = self.angle_deg.to_radians();
        let turn = [WALL_X - 1.0, yc, zc];
        let start = [turn[0] - a.cos(), turn[1] - a.sin(), zc];
        let mut route = vec![start, turn, [WALL_X + lay.t + 0.8, yc, zc]];
        if let Some(d) = lay.door {
            d.wall(&mut g, size);
            let yd = (d.y.0 + d.y.1) / 2.0;
            route.push([d.x - 0.8, yd, zc]);
            goal = [d.x + 0.2 + 1.5, yd, zc];
        }
        route.push(goal);
        let slit_text = match self.slits {
            Some((w, k)) => format!(" (in its place {k} slits {w} m wide, {SLIT_HEIGHT} m tall)"),
            None => String::new(),
        };
        let door_text = match self.door {
            Some((d, o)) => format!(
                ", then a second wall {} m behind it with a door {d} m wide ({o:+} m off the axis)",
                self.gap
            ),
            None => String::new(),
        };
        Ok(Scenario {
            name: self.name(),
            description: format!(
                "A room at {r} m with a {t} m wall holding a {w} m x {w} m window{slit_text} (a tunnel when the wall is thick) {off:+} m off the \
                 axis, approached at {ang} degrees off its normal{door_text}.",
                t = lay.t,
                w = self.w,
                off = self.offset,
                ang = self.angle_deg
            ),
            grid: g,
            start: start.into(),
            start_yaw: a,
            goal: goal.into(),
            default_units: 5,
            route: super::scenarios::points(&route),
        })
    }

    /// Each opening of the instance alone: a map that holds only the wall around it
    /// (so that the rest of the room does not count when a plan's clearance through
    /// it is measured, `crate::witness::opening_clearances`), with its width (its
    /// narrower side as built). `Err` when the instance does not build.
    pub fn opening_walls(&self) -> Result<Vec<OpeningWall>, ProblemError> {
        self.check()?;
        let r = self.res;
        let lay = self.layout();
        let size = lay.size(r);
        let empty = || Grid::new(r, [0; 3], lay.dims, Cell::Free, false);
        let mut walls = Vec::new();
        let mut grid = empty()?;
        lay.first_wall(&mut grid, self.sealed);
        let window = lay
            .openings(r)
            .iter()
            .map(|(y, z)| (y.1 - y.0).min(z.1 - z.0))
            .fold(f64::INFINITY, f64::min);
        walls.push(OpeningWall {
            name: if self.slits.is_some() {
                "slits"
            } else {
                "window"
            },
            grid,
            width: window,
        });
        if let Some(d) = lay.door {
            let mut grid = empty()?;
            d.wall(&mut grid, size);
            walls.push(OpeningWall {
                name: "door",
                grid,
                width: d.y.1 - d.y.0,
            });
        }
        Ok(walls)
    }
}

/// One opening of an instance and the wall that holds it, alone on a map.
#[derive(Clone, Debug)]
pub struct OpeningWall {
    /// `window`, `slits` or `door`.
    pub name: &'static str,
    /// A map of the instance's room holding only this wall.
    pub grid: Grid,
    /// The opening's width as built (m).
    pub width: f64,
}

/// Walls and openings of an instance, their faces on the map's lattice.
#[derive(Clone, Copy, Debug)]
struct Layout {
    /// Voxels per axis.
    dims: [usize; 3],
    /// First wall's thickness (m), from `WALL_X`.
    t: f64,
    /// Window faces across the room (y) and in height (z), m.
    window_y: (f64, f64),
    window_z: (f64, f64),
    /// The second wall, when there is one.
    door: Option<Door>,
    /// Slits in place of the window: width (m) and count.
    slits: Option<(f64, u32)>,
}

impl Layout {
    fn size(&self, r: f64) -> [f64; 3] {
        self.dims.map(|d| d as f64 * r)
    }

    fn window_centre(&self) -> (f64, f64) {
        (
            (self.window_y.0 + self.window_y.1) / 2.0,
            (self.window_z.0 + self.window_z.1) / 2.0,
        )
    }

    /// Puts the first wall into `g`, with its window (or its slits) unless `sealed`.
    fn first_wall(&self, g: &mut Grid, sealed: bool) {
        let size = self.size(g.resolution());
        let x1 = WALL_X + self.t;
        fill(
            g,
            [WALL_X, 0.0, 0.0],
            [x1, size[1], size[2]],
            Cell::Occupied,
        );
        if sealed {
            return;
        }
        for (y, z) in self.openings(g.resolution()) {
            fill(g, [WALL_X, y.0, z.0], [x1, y.1, z.1], Cell::Free);
        }
    }

    /// The first wall's openings, their faces across the room (y) and in height (z):
    /// the window, or the slits in its place.
    fn openings(&self, r: f64) -> Vec<((f64, f64), (f64, f64))> {
        let Some((w, k)) = self.slits else {
            return vec![(self.window_y, self.window_z)];
        };
        // The fewest whole voxels at least `w` wide, on the lattice nearest the centre.
        let voxels = (w / r - 1e-6).ceil();
        let span = |c: f64, v: f64| {
            let lo = ((c - v * r / 2.0) / r).round() * r;
            (lo, lo + v * r)
        };
        let (yc, _) = self.window_centre();
        let z = span(Z_C, (SLIT_HEIGHT / r).round());
        (0..k)
            .map(|i| {
                let c = yc + (i as f64 - (k - 1) as f64 / 2.0) * SLIT_PITCH;
                (span(c, voxels), z)
            })
            .collect()
    }
}

/// The second wall (0.2 m thick) and its door, from the floor's shell to 2 m.
#[derive(Clone, Copy, Debug)]
struct Door {
    /// Where the wall begins (m).
    x: f64,
    /// Door faces across the room (m).
    y: (f64, f64),
}

impl Door {
    fn wall(&self, g: &mut Grid, size: [f64; 3]) {
        let x1 = self.x + 0.2;
        fill(
            g,
            [self.x, 0.0, 0.0],
            [x1, size[1], size[2]],
            Cell::Occupied,
        );
        fill(
            g,
            [self.x, self.y.0, SHELL],
            [x1, self.y.1, 2.0],
            Cell::Free,
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_ranges_are_checked() {
        let s = PassageSpec::parse("w=0.5,angle=45,door=0.7,door_offset=-0.2").unwrap();
        assert_eq!(s.door, Some((0.7, -0.2)));
        assert_eq!(
            PassageSpec::parse(&s.name()["passage:".len()..]).unwrap(),
            s
        );
        assert!(PassageSpec::parse("w=0.3").is_err());
        assert!(PassageSpec::parse("angle=80").is_err());
        assert!(PassageSpec::parse("nope=1").is_err());
        assert!(PassageSpec::parse("w").is_err());
    }

    #[test]
    fn slits_replace_the_window_whole_voxels_wide() {
        let s = PassageSpec::parse("slit=0.2,slits=3,res=0.087").unwrap();
        assert_eq!(s.slits, Some((0.2, 3)));
        assert_eq!(
            PassageSpec::parse(&s.name()["passage:".len()..]).unwrap(),
            s
        );
        assert!(PassageSpec::parse("slit=0.2,slits=6").is_err());
        assert!(PassageSpec::parse("slit=0.2,slits=1.5").is_err());
        assert!(PassageSpec::parse("slit=0.4").is_err());
        let sc = s.build().unwrap();
        let (g, x) = (&sc.grid, WALL_X + 0.1);
        let y = ROOM_Y / 2.0;
        // The window's place is a slit; beside it, wall; a pitch on, the next slit.
        assert!(!g.is_obstacle_at([x, y, Z_C]));
        assert!(g.is_obstacle_at([x, y + 0.3, Z_C]));
        assert!(!g.is_obstacle_at([x, y + SLIT_PITCH, Z_C]));
        assert!(!g.is_obstacle_at([x, y - SLIT_PITCH, Z_C]));
        assert!(g.is_obstacle_at([x, y + 2.0 * SLIT_PITCH, Z_C]));
        // Three voxels of 0.087 m: the smallest whole number at least 0.2 m wide.
        let walls = s.opening_walls().unwrap();
        assert_eq!(walls[0].name, "slits");
        assert!(
            (walls[0].width - 3.0 * 0.087).abs() < 1e-9,
            "{}",
            walls[0].width
        );
    }

    #[test]
    fn the_window_is_as_wide_as_asked() {
        let s = PassageSpec::default();
        let sc = s.build().unwrap();
        // The wall is solid beside the window and open in it.
        let g = &sc.grid;
        let y = ROOM_Y / 2.0;
        assert!(!g.is_obstacle_at([WALL_X + 0.1, y, Z_C]));
        assert!(g.is_obstacle_at([WALL_X + 0.1, y + 0.3, Z_C]));
        assert!(g.is_obstacle_at([WALL_X + 0.1, y, Z_C + 0.3]));
    }
}
