//! The committed C header, `capi/include/specfx.h`, is what cbindgen generates from
//! `capi/src/lib.rs` today: a stale header fails here (regenerate it with
//! `SPECFX_BLESS=1 cargo test -p specfx-capi --test header`).

use std::path::Path;

#[test]
fn the_committed_header_is_what_cbindgen_generates() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let config = cbindgen::Config::from_file(dir.join("cbindgen.toml")).expect("cbindgen.toml");
    let mut generated = Vec::new();
    cbindgen::Builder::new()
        .with_config(config)
        .with_src(dir.join("src/lib.rs"))
        .generate()
        .expect("cbindgen reads src/lib.rs")
        .write(&mut generated);
    let path = dir.join("include/specfx.h");
    if std::env::var_os("SPECFX_BLESS").is_some() {
        std::fs::write(&path, &generated).expect("write the header");
    }
    let committed = std::fs::read(&path).unwrap_or_default();
    assert!(
        committed == generated,
        "{} is stale: regenerate it with SPECFX_BLESS=1 cargo test -p specfx-capi --test header",
        path.display()
    );
}
