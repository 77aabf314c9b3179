//! Man pages generated from the clap definitions (clap_mangen), so the pages and the
//! parser never disagree. `tests/cli/man_pages.rs` fails when `man/` is stale.

use clap::CommandFactory;

use super::args::Cli;

/// Every man page: `patchtrace.1` and one `patchtrace-<sub>.1` per subcommand, as
/// (file name, roff bytes).
pub fn man_pages() -> std::io::Result<Vec<(String, Vec<u8>)>> {
    let cmd = Cli::command();
    let mut pages = Vec::new();
    let mut buf = Vec::new();
    clap_mangen::Man::new(cmd.clone()).render(&mut buf)?;
    pages.push(("patchtrace.1".to_string(), buf));
    for sub in cmd.get_subcommands() {
        let name = format!("patchtrace-{}", sub.get_name());
        let sub = sub.clone().name(name.clone());
        let mut buf = Vec::new();
        clap_mangen::Man::new(sub).render(&mut buf)?;
        pages.push((format!("{name}.1"), buf));
    }
    Ok(pages)
}
