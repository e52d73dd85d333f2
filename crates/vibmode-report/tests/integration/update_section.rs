//! The model update's report section: what it says of the anti-roll bars, and of the updated
//! vehicle file only where one is written.

use vibmode_report::ReportSection;
use vibmode_vehicle::update::{BodyFit, BodyFitParams};
use vibmode_vehicle::{simulate, RoadClass, SimParams, VehicleParams};

/// Records of vibmode's rigid bus with its front anti-roll bar, fitted with a file without one:
/// the section names the bar the records give; it says the updated vehicle file has it when the
/// fit is used, and says nothing of a file when the fit is not (no file is written then).
#[test]
fn the_section_names_a_bar_the_file_lacks_and_a_file_only_where_written() {
    let truth = VehicleParams::city_bus();
    let mut file = truth.clone();
    file.front.anti_roll_stiffness_nm_per_rad = 0.0;
    let sp = SimParams {
        road: RoadClass::C,
        speed_kmh: 40.0,
        fs_hz: 200.0,
        records: 4,
        seed: 3,
        ..SimParams::default()
    };
    let mut fit = BodyFit::new(&file, BodyFitParams::default()).unwrap();
    for r in simulate(&truth, &sp).unwrap().records {
        fit.add_record(&r.recording).unwrap();
    }
    let res = fit.solve().unwrap();
    let text = |s: &ReportSection| s.paragraphs.join(" ");
    let used = text(&ReportSection::model_update(&file, &res, &[]));
    let found = res.found_bars(&file);
    assert_eq!(found.len(), 1, "{found:?}");
    assert!(
        used.contains(&format!("The records give a {}", found[0]))
            && used.contains("which the vehicle file lacks")
            && used.contains("the updated vehicle file has it"),
        "{used}"
    );
    let unused = text(&ReportSection::model_update_unsupported(
        &file,
        &res,
        &[],
        "a reason",
    ));
    assert!(
        unused.contains(&format!("The records give a {}", found[0]))
            && !unused.contains("the updated vehicle file has it"),
        "{unused}"
    );
}
