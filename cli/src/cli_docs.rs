//! docs/cli.md, the command-line reference, written from the clap definitions: every command
//! and subcommand with its usage, arguments, options, defaults, values and conflicts, as
//! Markdown for the mdBook in docs/. [`cli_reference_is_current`] fails when the checked-in
//! page differs from what the definitions give, and says how to write it anew.

use std::fmt::Write;

use clap::{Arg, ArgAction, Command, CommandFactory};

/// How to write docs/cli.md anew (said by the page and by the failing test).
const REGENERATE: &str = "GTSPHERE_WRITE_DOCS=1 cargo test -p gtsphere-cli cli_reference";

/// The reference page for the whole command.
pub fn markdown() -> String {
    let mut cmd = crate::Cli::command();
    // Built, the subcommands know their full names (`gtsphere bench parse`) and the flags
    // their implicit defaults; the help and version flags and the `help` subcommand that
    // building adds are left out below.
    cmd.build();
    let mut out = String::new();
    let _ = writeln!(out, "# Command-line reference\n");
    let _ = writeln!(
        out,
        "<!-- Written from the command's argument definitions by `{REGENERATE}`: \
         change the help texts, then run that; do not edit this page by hand. -->\n"
    );
    let name = cmd.get_name();
    let _ = writeln!(
        out,
        "`{name}`: {} This page holds the help of every command, as `{name} COMMAND --help` \
         prints it; `{name} --version` prints the version.\n",
        summary(cmd.get_about()),
    );
    command(&mut out, &cmd, 1);
    out
}

/// The subcommands worth a section (not `help`, not hidden ones).
fn subcommands(cmd: &Command) -> impl Iterator<Item = &Command> {
    cmd.get_subcommands()
        .filter(|c| !c.is_hide_set() && c.get_name() != "help")
}

/// The arguments worth an entry (not hidden ones, not `--help` and `--version`).
fn arguments(cmd: &Command) -> impl Iterator<Item = &Arg> {
    cmd.get_arguments().filter(|a| {
        !a.is_hide_set()
            && !matches!(
                a.get_action(),
                ArgAction::Help | ArgAction::HelpShort | ArgAction::HelpLong | ArgAction::Version
            )
    })
}

/// The full name of `cmd` (`gtsphere bench parse`), its heading's text.
fn full_name(cmd: &Command) -> String {
    cmd.get_bin_name().unwrap_or(cmd.get_name()).to_string()
}

/// The anchor mdBook gives a heading made of the code span `name`.
fn anchor(name: &str) -> String {
    name.replace(' ', "-")
}

/// The section of `cmd` at heading `level` (1: the top command, whose section has no
/// heading of its own), then those of its subcommands.
fn command(out: &mut String, cmd: &Command, level: usize) {
    let name = full_name(cmd);
    if level > 1 {
        let _ = writeln!(out, "{} `{name}`\n", "#".repeat(level));
        let about = cmd.get_long_about().or(cmd.get_about());
        for para in paragraphs(&text(about)) {
            let _ = writeln!(out, "{}\n", sentence(&para));
        }
    }
    let usage = cmd.clone().render_usage().to_string();
    let usage: Vec<&str> = usage
        .trim_start_matches("Usage:")
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect();
    let _ = writeln!(out, "```text\n{}\n```\n", usage.join("\n"));
    let subs: Vec<&Command> = subcommands(cmd).collect();
    if !subs.is_empty() {
        let _ = writeln!(out, "**Commands**\n");
        for sub in &subs {
            let sub_name = full_name(sub);
            let _ = writeln!(
                out,
                "- [`{sub_name}`](#{}): {}",
                anchor(&sub_name),
                summary(sub.get_about())
            );
        }
        out.push('\n');
    }
    let (positionals, options): (Vec<&Arg>, Vec<&Arg>) =
        arguments(cmd).partition(|a| a.is_positional());
    for (title, list) in [("Arguments", positionals), ("Options", options)] {
        if list.is_empty() {
            continue;
        }
        let _ = writeln!(out, "**{title}**\n");
        for arg in list {
            argument(out, cmd, arg);
        }
        out.push('\n');
    }
    for sub in subs {
        command(out, sub, level + 1);
    }
}

/// One argument as a list item: how it is written, its help, default, values, conflicts.
fn argument(out: &mut String, cmd: &Command, arg: &Arg) {
    let value = arg
        .get_value_names()
        .and_then(|v| v.first())
        .map(|v| v.to_string())
        .unwrap_or_else(|| arg.get_id().as_str().to_uppercase());
    let takes_value = arg.get_action().takes_values();
    let spelled = if arg.is_positional() {
        let many = matches!(arg.get_action(), ArgAction::Append);
        format!("<{value}>{}", if many { "..." } else { "" })
    } else {
        let mut s = match (arg.get_short(), arg.get_long()) {
            (Some(c), Some(l)) => format!("-{c}, --{l}"),
            (Some(c), None) => format!("-{c}"),
            (None, Some(l)) => format!("--{l}"),
            (None, None) => arg.get_id().to_string(),
        };
        if takes_value {
            let _ = write!(s, " <{value}>");
        }
        s
    };
    let help = arg.get_long_help().or(arg.get_help());
    let paras = paragraphs(&text(help));
    let mut first = paras.first().map(|p| sentence(p)).unwrap_or_default();
    let defaults: Vec<String> = arg
        .get_default_values()
        .iter()
        .map(|v| format!("`{}`", v.to_string_lossy()))
        .collect();
    if takes_value && !defaults.is_empty() {
        let _ = write!(first, " Default: {}.", defaults.join(", "));
    }
    let conflicts = conflicts(cmd, arg);
    if !conflicts.is_empty() {
        let _ = write!(first, " Not with {}.", conflicts.join(", "));
    }
    let _ = writeln!(out, "- `{spelled}`: {}", first.trim_start());
    for para in paras.iter().skip(1) {
        let _ = writeln!(out, "\n  {}", sentence(para));
    }
    let values: Vec<_> = arg
        .get_possible_values()
        .into_iter()
        .filter(|v| !v.is_hide_set())
        .collect();
    if takes_value && !values.is_empty() && !arg.is_positional() {
        if values.iter().any(|v| v.get_help().is_some()) {
            for v in values {
                let _ = match v.get_help() {
                    Some(h) => {
                        writeln!(out, "  - `{}`: {}", v.get_name(), summary(Some(h)))
                    }
                    None => writeln!(out, "  - `{}`", v.get_name()),
                };
            }
        } else {
            let names: Vec<String> = values
                .iter()
                .map(|v| format!("`{}`", v.get_name()))
                .collect();
            let _ = writeln!(out, "\n  Values: {}.", names.join(", "));
        }
    }
}

/// The options `arg` cannot be given with, either way round, as `--name` code spans.
fn conflicts(cmd: &Command, arg: &Arg) -> Vec<String> {
    let mut ids: Vec<&Arg> = cmd.get_arg_conflicts_with(arg);
    for other in cmd.get_arguments() {
        if other.get_id() != arg.get_id()
            && cmd
                .get_arg_conflicts_with(other)
                .iter()
                .any(|a| a.get_id() == arg.get_id())
            && !ids.iter().any(|a| a.get_id() == other.get_id())
        {
            ids.push(other);
        }
    }
    ids.iter()
        .map(|a| match a.get_long() {
            Some(l) => format!("`--{l}`"),
            None => format!("`<{}>`", a.get_id().as_str().to_uppercase()),
        })
        .collect()
}

/// A one-paragraph help text as a Markdown sentence.
fn summary(s: Option<&clap::builder::StyledStr>) -> String {
    sentence(&paragraphs(&text(s)).join(" "))
}

/// A help text as plain text.
fn text(s: Option<&clap::builder::StyledStr>) -> String {
    s.map(|s| s.to_string()).unwrap_or_default()
}

/// The paragraphs of a help text, each on one line, as Markdown.
fn paragraphs(s: &str) -> Vec<String> {
    s.split("\n\n")
        .map(|p| p.split_whitespace().collect::<Vec<_>>().join(" "))
        .filter(|p| !p.is_empty())
        .map(|p| inline(&p))
        .collect()
}

/// `p` ending as a sentence does (clap drops the full stop of a one-line help text).
fn sentence(p: &str) -> String {
    let p = p.trim();
    if p.is_empty() || p.ends_with(['.', '!', '?', ':']) {
        p.to_string()
    } else {
        format!("{p}.")
    }
}

/// Plain help text as Markdown: code spans (between backticks) kept, option names
/// (`--name`) made code spans, and the characters Markdown would read as markup escaped.
fn inline(p: &str) -> String {
    let mut out = String::with_capacity(p.len() + 16);
    let chars: Vec<char> = p.chars().collect();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        if c == '`' {
            if let Some(len) = chars[i + 1..].iter().position(|&d| d == '`') {
                out.extend(&chars[i..=i + 1 + len]);
                i += len + 2;
                continue;
            }
        }
        let starts_word = i == 0 || !(chars[i - 1].is_alphanumeric() || chars[i - 1] == '-');
        if c == '-'
            && starts_word
            && chars.get(i + 1) == Some(&'-')
            && chars.get(i + 2).is_some_and(|d| d.is_ascii_lowercase())
        {
            let end = (i + 2..chars.len())
                .find(|&k| !(chars[k].is_ascii_alphanumeric() || chars[k] == '-'))
                .unwrap_or(chars.len());
            out.push('`');
            out.extend(&chars[i..end]);
            out.push('`');
            i = end;
            continue;
        }
        let inside_word = |k: usize| {
            k > 0
                && chars[k - 1].is_alphanumeric()
                && chars.get(k + 1).is_some_and(|d| d.is_alphanumeric())
        };
        match c {
            '\\' | '*' | '<' | '[' | ']' | '~' => out.push('\\'),
            '_' if !inside_word(i) => out.push('\\'),
            _ => {}
        }
        out.push(c);
        i += 1;
    }
    out
}

/// docs/cli.md is what the definitions give. With `GTSPHERE_WRITE_DOCS=1`, writes it instead.
#[test]
fn cli_reference_is_current() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/cli.md");
    let want = markdown();
    if std::env::var_os("GTSPHERE_WRITE_DOCS").is_some_and(|v| v == "1") {
        std::fs::write(&path, &want).expect("write docs/cli.md");
        return;
    }
    let have = std::fs::read_to_string(&path).unwrap_or_default();
    if have != want {
        let line = have
            .lines()
            .zip(want.lines())
            .position(|(a, b)| a != b)
            .unwrap_or_else(|| have.lines().count().min(want.lines().count()));
        panic!(
            "docs/cli.md differs from the command's help texts (first at line {}:\n  page:    \
             {:?}\n  command: {:?}).\nWrite it anew with `{REGENERATE}`.",
            line + 1,
            have.lines().nth(line).unwrap_or("(end of page)"),
            want.lines().nth(line).unwrap_or("(end of page)"),
        );
    }
}

#[test]
fn help_text_becomes_markdown() {
    assert_eq!(
        inline("with --scaling, N <= 1e4 [default: 2]; `a_b*` stays; x_y"),
        "with `--scaling`, N \\<= 1e4 \\[default: 2\\]; `a_b*` stays; x_y"
    );
    assert_eq!(inline("tol * 1e-3, _x"), "tol \\* 1e-3, \\_x");
    assert_eq!(inline("as --region."), "as `--region`.");
    assert_eq!(sentence("Width in pixels"), "Width in pixels.");
    assert_eq!(sentence("(default: 1)."), "(default: 1).");
}
