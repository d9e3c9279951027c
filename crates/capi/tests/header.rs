//! The committed C header `include/flapssm.h` is what cbindgen generates from the sources
//! (`FLAPSSM_BLESS=1 cargo test -p flapssm-capi --test header` rewrites it).

use std::path::Path;

#[test]
fn the_committed_header_is_generated_from_the_sources() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let config = cbindgen::Config::from_file(root.join("cbindgen.toml")).unwrap();
    let mut generated = Vec::new();
    cbindgen::Builder::new()
        .with_config(config)
        .with_src(root.join("src/lib.rs"))
        .generate()
        .expect("cbindgen parses the C interface")
        .write(&mut generated);
    let generated = String::from_utf8(generated).unwrap();
    for name in [
        "flapssm_model_load",
        "flapssm_stream_step_f32_arrays",
        "flapssm_last_error",
        "FLAPSSM_STATUS_SHAPE",
    ] {
        assert!(generated.contains(name), "{name} missing from the header");
    }
    let path = root.join("include/flapssm.h");
    if std::env::var_os("FLAPSSM_BLESS").is_some() {
        std::fs::write(&path, &generated).unwrap();
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        committed == generated,
        "{} is out of date: run FLAPSSM_BLESS=1 cargo test -p flapssm-capi --test header",
        path.display()
    );
}
