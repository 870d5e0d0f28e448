//! The generated stress cases (`asp gen stress`) — chairs with rungs in two
//! legs on two or four sides, carcasses of panels joined by dowels (holes modelled or dowels
//! drawn into solid panels), plates clamped by threaded bolts and nuts — are taken apart
//! completely (`found`), and every plan passes the independent re-check of
//! `asp_check::verify` (point containment at sampled poses: no part enters material of a
//! present part it did not already overlap).

use crate::fuzz::removals;
use crate::verify::verify_plan;
use asp_app::pipeline::{checker, plan_assembly, PlanSettings};
use asp_gen::batch::{generate_item, Generator};
use asp_gen::{StressKind, StressParams};
use asp_search::report::{MotionEntry, PlanStatus};
use asp_search::{PlanOutcome, Status};

/// Assemblies per kind (batch seed 7): chairs with rungs on two and on four sides, carcasses
/// with and without holes, one to four bolts.
const PER_KIND: usize = 6;

#[test]
fn stress_cases_come_apart_completely_and_pass_the_re_check() {
    let settings = PlanSettings::default();
    let (mut groups, mut drawn, mut screws) = (0, 0, 0);
    for stress in [StressKind::Chair, StressKind::Carcass, StressKind::Bolted] {
        let generator = Generator::Stress(StressParams { stress });
        for index in 0..PER_KIND {
            let (generated, entry) = generate_item(&generator, index, PER_KIND, 7).unwrap();
            let what = format!("{} {index}", stress.name());
            assert!(entry.checks.passed() && entry.checks.contact_linked, "{what}: {:?}", entry.checks);
            let assembly = generated.assembly;
            let n = assembly.len();
            let r = plan_assembly(assembly.clone(), &settings, None).unwrap();
            assert_eq!(r.report.status, PlanStatus::Found, "{what}: {}", r.report.to_text());
            assert!(r.report.locked_cores.is_empty(), "{what}");
            let steps = &r.report.assembly_sequence;
            groups += steps.iter().filter(|s| s.subassembly.is_some()).count();
            screws += steps.iter().filter(|s| matches!(s.motion, MotionEntry::Screw { .. })).count();
            if entry.checks.max_penetration > 1e-3 {
                // dowels drawn into solid panels leave along their axis (x), never sideways
                drawn += 1;
                for s in steps.iter().filter(|s| s.name.starts_with("dowel")) {
                    let MotionEntry::Linear { direction, .. } = s.motion else { panic!("{what}: {} not straight", s.name) };
                    assert!(direction[0].abs() > 0.999, "{what}: {} leaves along {direction:?}, through a panel", s.name);
                }
            }
            let world = checker(assembly, &settings).unwrap();
            let outcome = PlanOutcome { status: Status::Found, removals: removals(steps, n), stats: Default::default() };
            verify_plan(world.world(), &outcome);
        }
    }
    // the cases exercise what they are for: a leg pair leaving with its rung, dowels drawn into
    // solid panels, nuts and bolts turned off
    assert!(groups > 0 && drawn > 0 && screws > 0, "groups {groups}, carcasses without holes {drawn}, screw motions {screws}");
}
