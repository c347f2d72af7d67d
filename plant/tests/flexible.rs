//! The flexible rotor in the plant (`rotor.model = "flexible"`, `plant/src/machine/flexible.rs`):
//! its `Machine` at its nodes, and a stiff shaft against the rigid two-plane rotor. Here, not in
//! the module, so that `machine` does not depend on `config` and `run` (tests/tests/modules.rs).

use plant::machine::Machine;
use plant::model::Control;
use plant_physics::flex::machine::{ix, Model};

mod tests {
    use super::*;
    use plant::config::{load_scene, Rotor};
    use std::path::Path;

    fn scene() -> plant::config::Scene {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../config/flexible-10g.toml");
        load_scene(&path, &[]).expect("the shipped flexible scene loads")
    }

    fn model(scene: &plant::config::Scene) -> Model {
        let Rotor::Flexible(params) = &scene.rotor else { panic!("a flexible scene") };
        Model {
            params: params.clone(),
            base: scene.base.clone(),
            control: [Control::Held([0.0; 2]); 2],
            race_parked: [false; 2],
        }
    }

    /// A rigid translation and tilt put into the flexible state reads back at every node as
    /// the rigid rotor's axis there: at the sensors, at the touchdown nodes, and in the slopes.
    #[test]
    fn a_rigid_motion_reads_back_at_its_nodes() {
        let scene = scene();
        let m = model(&scene);
        let mut rigid = [0.0; plant_physics::two_plane::N];
        use plant_physics::two_plane::ix as r;
        rigid[r::X] = 3e-6;
        rigid[r::Y] = -2e-6;
        rigid[r::SX] = 1e-5;
        rigid[r::SY] = -4e-5;
        rigid[r::VX] = 1e-3;
        rigid[r::WR] = 100.0;
        let y = Model::from_rigid(&m.params, &rigid);
        for i in 0..2 {
            let z = m.params.z[m.params.nodes[i].sensor];
            let [x, yy] = m.sensed(&y, i);
            assert!((x - (3e-6 + 1e-5 * z)).abs() < 1e-12, "plane {i}: x {x}");
            assert!((yy - (-2e-6 - 4e-5 * z)).abs() < 1e-12, "plane {i}: y {yy}");
            let [vx, _] = m.sensed_rate(&y, i);
            assert!((vx - 1e-3).abs() < 1e-12, "plane {i}: vx {vx}");
        }
        // The line through the two sensors has the rigid motion's slopes.
        let z = [0, 1].map(|i| m.params.z[m.params.nodes[i].sensor]);
        let (a, b) = (m.sensed(&y, 0), m.sensed(&y, 1));
        let s = [(b[0] - a[0]) / (z[1] - z[0]), (b[1] - a[1]) / (z[1] - z[0])];
        assert!((s[0] - 1e-5).abs() < 1e-12 && (s[1] + 4e-5).abs() < 1e-12, "{s:?}");
        assert_eq!(m.spin(&y), (0.0, 100.0));
    }

    /// Plane i's touchdown bearing is where the model says: the rotor pushed against race A's
    /// side at its touchdown node touches race A and not race B.
    #[test]
    fn touching_is_at_the_touchdown_node() {
        let scene = scene();
        let m = model(&scene);
        let gap = m.bearing(0).contact.gap;
        let mut rigid = [0.0; plant_physics::two_plane::N];
        use plant_physics::two_plane::ix as r;
        // A tilt about touchdown node B: node B stays, node A moves by 1.5 gaps.
        let [za, zb] = [0, 1].map(|i| m.params.z[m.params.nodes[i].touchdown]);
        let slope = 1.5 * gap / (za - zb);
        rigid[r::SX] = slope;
        rigid[r::X] = -slope * zb;
        let y = Model::from_rigid(&m.params, &rigid);
        assert!(m.touching(&y, 0));
        assert!(!m.touching(&y, 1));
        let (ra, _) = m.radii(&y, 0);
        assert!((ra - 1.5 * gap).abs() < 1e-9 * gap, "{ra}");
        let rec = m.record(0.0, &y);
        assert!(rec.a[12] > 0.0, "contact force at A: {}", rec.a[12]);
        assert_eq!(rec.b.unwrap()[9], 0.0, "no contact at B");
    }

    /// Every slot past the basis' size stays zero under the derivative.
    #[test]
    fn the_unused_slots_stay_at_rest() {
        let scene = scene();
        let m = model(&scene);
        let r = m.params.reduced.size();
        let y = Model::from_rigid(&m.params, &plant::initial::two_plane_initial_state(&scene, &m.params.machine));
        let dy = m.evaluate(0.0, &y).dy;
        assert!(dy[r..ix::TR].iter().chain(&dy[ix::V + r..ix::WR]).all(|v| *v == 0.0));
    }
}

mod convergence {
    use plant::config::{load_scene, Rotor, Scene};
    use std::path::Path;

    /// The flexible scene, shortened, with its shaft's moduli scaled by `stiffer` and the shock
    /// at `peak_g`; and the same machine as the rigid two-plane rotor (its rigid body, the same
    /// bearings, stations and sensors).
    pub(super) fn pair(stiffer: f64, peak_g: f64, duration: f64) -> (Scene, Scene) {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../config/flexible-10g.toml");
        let sets = [
            format!("rotor.shaft.materials.steel.modulus_pa={:e}", 211e9 * stiffer),
            format!("rotor.shaft.materials.steel.shear_modulus_pa={:e}", 81.2e9 * stiffer),
            format!("scene.duration_s={duration}"),
            format!("shock[0].peak_g={peak_g:?}"),
            "output.plots=false".to_string(),
        ];
        let flexible = load_scene(&path, &sets).expect("the flexible scene loads");
        let Rotor::Flexible(f) = &flexible.rotor else { panic!("a flexible scene") };
        let mut rigid = flexible.clone();
        rigid.rotor = Rotor::TwoPlane(f.machine.clone());
        (flexible, rigid)
    }

    /// The largest difference between two runs' rotor positions at both bearing planes, over
    /// the largest of the rigid run's (relative).
    pub(super) fn difference(a: &Scene, b: &Scene) -> f64 {
        let quiet = &mut plant::hooks::Quiet;
        let ta = plant::run::run(a, quiet).expect("runs").trace;
        let tb = plant::run::run(b, quiet).expect("runs").trace;
        assert_eq!(ta.len(), tb.len());
        let (ba, bb) = (ta.b.as_ref().unwrap(), tb.b.as_ref().unwrap());
        let cols = |t: &plant::trace::Trace, b: &plant::trace::TraceB, i: usize| {
            [t.dx_m[i], t.dy_m[i], b.b_dx_m[i], b.b_dy_m[i]]
        };
        let (mut diff, mut size) = (0.0f64, 0.0f64);
        for i in 0..ta.len() {
            let (x, y) = (cols(&ta, ba, i), cols(&tb, bb, i));
            for k in 0..4 {
                diff = diff.max((x[k] - y[k]).abs());
                size = size.max(y[k].abs());
            }
        }
        diff / size
    }

    /// A stiff shaft converges to the rigid two-plane rotor: under a 1 G shock (no contact),
    /// the rotor's positions at both bearings differ by less than 1 % of their largest with the
    /// shaft 1000 times stiffer than steel, and the difference falls as the shaft stiffens.
    #[test]
    fn a_stiff_shaft_converges_to_the_two_plane_rotor() {
        let mut last = f64::INFINITY;
        for stiffer in [1.0, 1e3] {
            let (f, r) = pair(stiffer, 1.0, 0.08);
            let d = difference(&f, &r);
            eprintln!("shaft {stiffer:e} x steel: relative difference {d:.3e}");
            assert!(d < last, "{d} after {last}");
            last = d;
        }
        assert!(last < 1e-2, "{last}");
    }
}
