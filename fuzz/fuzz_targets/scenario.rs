//! Scenario files: any text through the parser and the validator never panics; a scenario they
//! accept builds a world that steps, and the `scenario.toml` a run saves validates again.
#![no_main]
use colcos_sim::scenario::Scenario;
use colcos_sim::world::World;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    // Relative image paths resolve against the shipped scenarios' folder.
    let base = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenarios");
    let Ok(scenario) = Scenario::from_toml_str(text, base) else {
        return;
    };
    let mut world = match World::new(&scenario) {
        Ok(w) => w,
        Err(e) => panic!("validation accepted a scenario the world refuses: {e}"),
    };
    world.step();
    if let Err(e) = Scenario::from_toml_str(&scenario.to_toml(), base) {
        panic!("the saved scenario does not validate again: {e}");
    }
});
