//! The checked-in `include/ampm.h` must be exactly what the pinned cbindgen generates from
//! `ffi/src`. Set `AMPM_BLESS=1` to rewrite it after changing the C ABI.

use std::path::PathBuf;

#[test]
fn header_matches_source() {
    let crate_dir = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let header = crate_dir.join("../include/ampm.h");
    let config = cbindgen::Config::from_file(crate_dir.join("cbindgen.toml"))
        .expect("ffi/cbindgen.toml parses");
    let bindings = cbindgen::Builder::new()
        .with_crate(&crate_dir)
        .with_config(config)
        .generate()
        .expect("cbindgen generates the header");
    let mut generated = Vec::new();
    bindings.write(&mut generated);
    let generated = String::from_utf8(generated).expect("header is UTF-8");
    if std::env::var_os("AMPM_BLESS").is_some() {
        std::fs::write(&header, &generated).expect("write include/ampm.h");
        return;
    }
    let checked_in = std::fs::read_to_string(&header).unwrap_or_default();
    assert!(
        checked_in == generated,
        "include/ampm.h differs from what cbindgen generates from ffi/src; \
         run `AMPM_BLESS=1 cargo test -p ampm-ffi --test header` and commit the result"
    );
}
