// The collision checks of two commits timed on identical cases: copied into a worktree
// of each as an example by `scripts/compare-checks`, which fills in the crate and module
// names each commit has (HOST, CORE, SCEN, DISTMOD). Modes:
//   gen OUT         2000 random SRS placements in `window` (N = 5) this commit accepts,
//                   each with a translation target 0.5 m away and a shape to change to
//   filter IN OUT   the cases whose placement this commit accepts too
//   translating IN OUT  the cases whose translation this commit accepts
//   time IN         medians of 15 passes: a translation and a shape change per case
//                   (scaled to 200 cases, as `cargo bench ... x200`), a placement per case
use std::io::Write;
use std::sync::atomic::AtomicUsize;
use std::sync::Arc;
use std::time::Instant;

use HOST::collision::{CollisionContext, DEFAULT_CLEARANCE};
use HOST::map::DISTMOD::DistanceField;
use HOST::SCEN::scenarios;
use HOST::tables::{ShapeTables, TableSettings};
use CORE::{ChainParams, Shape};
use rand::{Rng, SeedableRng};

type Case = ([f64; 3], [f64; 3], Shape, Shape);

/// The chain every case is for, and the angles of one of its shapes (head yaw, then
/// every link's pitch and yaw).
const UNITS: u8 = 5;
const ANGLES: usize = 2 * UNITS as usize - 1;

fn ctx_and_tables() -> (CollisionContext, ShapeTables) {
    let sc = scenarios::build("window").expect("built-in scenario");
    let field = Arc::new(DistanceField::new(sc.grid.clone()));
    let params = ChainParams::new(UNITS);
    let ctx = CollisionContext::new(field, params, DEFAULT_CLEARANCE).expect("valid chain");
    let tables = ShapeTables::build(params, &TableSettings::default(), &AtomicUsize::new(0))
        .expect("tables");
    (ctx, tables)
}

fn write(path: &str, cases: &[Case]) {
    let mut f = std::fs::File::create(path).unwrap();
    for (p, q, s, t) in cases {
        let mut v: Vec<String> = p.iter().chain(q).map(|x| format!("{x}")).collect();
        v.extend(s.as_slice().iter().map(|x| format!("{x}")));
        v.extend(t.as_slice().iter().map(|x| format!("{x}")));
        writeln!(f, "{}", v.join(" ")).unwrap();
    }
}

fn read(path: &str) -> Vec<Case> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .map(|l| {
            let v: Vec<&str> = l.split(' ').collect();
            let f = |i: usize| v[i].parse::<f64>().unwrap();
            let shape = |a: usize| {
                let eta: Vec<f32> = (a..a + ANGLES).map(|i| v[i].parse().unwrap()).collect();
                Shape::from_slice(UNITS, &eta).unwrap()
            };
            (
                [f(0), f(1), f(2)],
                [f(3), f(4), f(5)],
                shape(6),
                shape(6 + ANGLES),
            )
        })
        .collect()
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (ctx, tables) = ctx_and_tables();
    match args[1].as_str() {
        "gen" => {
            let mut rng = rand_pcg::Pcg64::seed_from_u64(11);
            let (lo, hi) = ctx.field().grid().bounds();
            let srs = &tables.srs;
            let cases: Vec<Case> = std::iter::repeat_with(|| {
                let p: [f64; 3] = std::array::from_fn(|a| rng.gen_range(lo[a]..hi[a]));
                let s = srs[rng.gen_range(0..srs.len())];
                let a: f64 = rng.gen_range(0.0..std::f64::consts::TAU);
                let t = srs[rng.gen_range(0..srs.len())];
                (p, [p[0] + 0.5 * a.cos(), p[1] + 0.5 * a.sin(), p[2]], s, t)
            })
            .filter(|(p, _, s, _)| ctx.check_placement(*p, s).is_ok())
            .take(2000)
            .collect();
            write(&args[2], &cases);
        }
        "filter" => {
            let v: Vec<Case> = read(&args[2])
                .into_iter()
                .filter(|(p, _, s, _)| ctx.check_placement(*p, s).is_ok())
                .collect();
            println!("kept {}", v.len());
            write(&args[3], &v);
        }
        "translating" => {
            let v: Vec<Case> = read(&args[2])
                .into_iter()
                .filter(|(p, q, s, _)| ctx.check_translation(*p, *q, s).is_ok())
                .collect();
            println!("kept {}", v.len());
            write(&args[3], &v);
        }
        "time" => {
            let cases = read(&args[2]);
            let n = cases.len() as f64;
            let mut tr = Vec::new();
            let mut sc = Vec::new();
            let mut pl = Vec::new();
            let mut oks = (0, 0, 0);
            for _ in 0..15 {
                let t = Instant::now();
                oks.0 = cases.iter().filter(|(p, q, s, _)| ctx.check_translation(*p, *q, s).is_ok()).count();
                tr.push(t.elapsed().as_secs_f64() / n * 200.0);
                let t = Instant::now();
                oks.1 = cases.iter().filter(|(p, _, s, u)| ctx.check_shape_change(*p, s, u).is_ok()).count();
                sc.push(t.elapsed().as_secs_f64() / n * 200.0);
                let t = Instant::now();
                for _ in 0..20 {
                    oks.2 = cases.iter().filter(|(p, _, s, _)| ctx.check_placement(*p, s).is_ok()).count();
                }
                pl.push(t.elapsed().as_secs_f64() / n / 20.0);
            }
            let med = |v: &mut Vec<f64>| {
                v.sort_by(f64::total_cmp);
                v[v.len() / 2]
            };
            println!(
                "cases {} ok {:?}: translation_x200 {:.1} us, shape_change_x200 {:.3} ms, placement {:.1} ns",
                cases.len(),
                oks,
                med(&mut tr) * 1e6,
                med(&mut sc) * 1e3,
                med(&mut pl) * 1e9
            );
        }
        _ => panic!("gen | filter | translating | time"),
    }
}
