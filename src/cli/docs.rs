//! `fbakit completions SHELL` and `fbakit man -o DIR`: shell completions and man pages
//! generated from the command definitions, so they never drift from `--help`.

use std::path::PathBuf;

use clap::CommandFactory;
use clap_complete::Shell;
use fbakit::error::{Error, Result};
use serde::Serialize;

use super::{print_json, Cli, EXIT_OK};

/// Arguments of `completions`.
#[derive(Debug, clap::Args)]
pub struct CompletionsArgs {
    /// The shell.
    #[arg(value_enum)]
    pub shell: Shell,
    /// Print `{"shell": ..., "script": ...}` instead of the bare script.
    #[arg(long)]
    pub json: bool,
}

/// Arguments of `man`.
#[derive(Debug, clap::Args)]
pub struct ManArgs {
    /// Output directory (created): fbakit.1 and fbakit-COMMAND[-SUB].1.
    #[arg(short, long, value_name = "DIR")]
    pub output: PathBuf,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
}

/// Prints a completion script.
pub fn completions(a: CompletionsArgs) -> Result<u8> {
    let mut cmd = Cli::command();
    let mut script = Vec::new();
    clap_complete::generate(a.shell, &mut cmd, "fbakit", &mut script);
    if a.json {
        print_json(&serde_json::json!({
            "shell": a.shell.to_string(),
            "script": String::from_utf8_lossy(&script),
        }))?;
    } else {
        use std::io::Write as _;
        std::io::stdout()
            .write_all(&script)
            .map_err(|e| Error::io("<stdout>", e))?;
    }
    Ok(EXIT_OK)
}

#[derive(Serialize)]
struct ManReport {
    directory: String,
    pages: Vec<String>,
}

/// Writes one man page per command and subcommand.
pub fn man(a: ManArgs) -> Result<u8> {
    if a.output.exists() && !a.output.is_dir() {
        return Err(Error::Usage(format!(
            "{}: --output must be a directory (it is a file)",
            a.output.display()
        )));
    }
    // All pages or none: written into a temporary sibling renamed into place. Earlier pages
    // are replaced; a folder holding other files is refused rather than replaced.
    let dir =
        fbakit::io::open_frame_dir(&a.output, |n| n.starts_with("fbakit") && n.ends_with(".1"))?;
    let mut pages = Vec::new();
    let mut cmd = Cli::command();
    cmd.build();
    write_pages(&cmd, "fbakit", &dir, &mut pages)?;
    dir.commit()?;
    let report = ManReport {
        directory: a.output.display().to_string(),
        pages,
    };
    if a.json {
        print_json(&report)?;
    } else {
        println!(
            "wrote {} man pages to {} (read one with `man -l {}/fbakit.1`)",
            report.pages.len(),
            report.directory,
            report.directory
        );
    }
    Ok(EXIT_OK)
}

/// Writes `name.1` for `cmd` and recurses into its subcommands (`name-sub.1`).
fn write_pages(
    cmd: &clap::Command,
    name: &str,
    dir: &fbakit::io::AtomicDir,
    pages: &mut Vec<String>,
) -> Result<()> {
    // Subcommand pages carry the full name in their title (`fbakit-play`).
    let page_cmd = cmd.clone().name(name.to_string());
    let mut roff = Vec::new();
    clap_mangen::Man::new(page_cmd)
        .render(&mut roff)
        .map_err(|e| Error::io(dir.path(), e))?;
    let file = format!("{name}.1");
    dir.write_file(&file, |p| fbakit::io::write_atomic(p, &roff))?;
    pages.push(file);
    for sub in cmd.get_subcommands().filter(|s| !s.is_hide_set()) {
        if sub.get_name() == "help" {
            continue;
        }
        write_pages(sub, &format!("{name}-{}", sub.get_name()), dir, pages)?;
    }
    Ok(())
}
