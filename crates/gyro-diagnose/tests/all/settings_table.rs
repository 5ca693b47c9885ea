//! The settings table in docs/diagnose.md is the one `Settings::markdown_table` renders
//! from the defaults. Regenerate it with
//! `UPDATE_DOCS=1 cargo test -p gyro-diagnose --test all settings_table::`.

use gyro_diagnose::Settings;
use std::path::PathBuf;

const BEGIN: &str = "<!-- settings table: generated from gyro_diagnose::Settings::markdown_table; regenerate with UPDATE_DOCS=1 cargo test -p gyro-diagnose --test all settings_table:: -->\n";
const END: &str = "<!-- end of the settings table -->";

#[test]
fn the_docs_table_is_the_settings() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../docs/diagnose.md");
    let text = std::fs::read_to_string(&path).expect("docs/diagnose.md");
    let start = text.find(BEGIN).expect("the settings table's begin marker") + BEGIN.len();
    let end = start
        + text[start..]
            .find(END)
            .expect("the settings table's end marker");
    let table = Settings::DEFAULT.markdown_table();
    if text[start..end] == table {
        return;
    }
    if std::env::var_os("UPDATE_DOCS").is_some() {
        let updated = format!("{}{}{}", &text[..start], table, &text[end..]);
        std::fs::write(&path, updated).expect("write docs/diagnose.md");
        return;
    }
    panic!(
        "docs/diagnose.md's settings table differs from Settings::markdown_table(); \
         regenerate it with: UPDATE_DOCS=1 cargo test -p gyro-diagnose --test all settings_table::\n\
         expected:\n{table}\nfound:\n{}",
        &text[start..end]
    );
}
