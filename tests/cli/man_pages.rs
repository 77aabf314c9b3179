//! The man pages in `man/` are generated from the clap definitions; this fails when they
//! are stale. Regenerate with `PATCHTRACE_UPDATE_MAN=1 cargo test --test cli man_pages`.

use std::path::Path;

#[test]
fn man_pages_match_the_command_line_definitions() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("man");
    let pages = patchtrace::cli::man::man_pages().expect("render man pages");
    if std::env::var_os("PATCHTRACE_UPDATE_MAN").is_some() {
        std::fs::create_dir_all(&dir).unwrap();
        for (name, bytes) in &pages {
            std::fs::write(dir.join(name), bytes).unwrap();
        }
    }
    let mut stale = Vec::new();
    for (name, bytes) in &pages {
        match std::fs::read(dir.join(name)) {
            Ok(on_disk) if &on_disk == bytes => {}
            _ => stale.push(name.clone()),
        }
    }
    assert!(
        stale.is_empty(),
        "stale or missing man pages: {stale:?}; run PATCHTRACE_UPDATE_MAN=1 cargo test --test cli man_pages"
    );
    // Every subcommand has a page and no page is left over from a removed command.
    let on_disk = std::fs::read_dir(&dir).unwrap().count();
    assert_eq!(
        on_disk,
        pages.len(),
        "man/ holds pages for commands that no longer exist"
    );
}
