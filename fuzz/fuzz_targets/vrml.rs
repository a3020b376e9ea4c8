//! VRML97 parser: never panics; whatever parses writes canonically and re-parses equal.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(scene) = fbakit::vrml::parse_vrml_str(text) {
        let written = fbakit::vrml::write_vrml_string(&scene);
        let again = fbakit::vrml::parse_vrml_str(&written)
            .unwrap_or_else(|e| panic!("canonical output does not parse: {e}\n{written}"));
        assert_eq!(again, scene, "round trip changed the scene:\n{written}");
        assert_eq!(fbakit::vrml::write_vrml_string(&again), written);
    }
});
