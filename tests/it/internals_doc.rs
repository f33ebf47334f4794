//! docs/internals.md's table of modules is made of the modules' own documentation: the first
//! sentence of each `.rs` file's `//!` comment in `src/`, `cli/src/` and `python/src/`. A new,
//! moved or re-documented module fails here until the page is made anew.

use std::path::{Path, PathBuf};

/// The page, from the crate root.
const PAGE: &str = "docs/internals.md";
/// Where the generated table starts and ends on the page.
const START: &str = "<!-- modules: made by tests/it/internals_doc.rs -->\n";
const END: &str = "<!-- end of modules -->\n";
/// The command that writes the table anew.
const REMAKE: &str = "GTSPHERE_WRITE_DOCS=1 cargo test --test it internals_doc";
/// The source folders, as the page names them.
const ROOTS: [&str; 3] = ["src", "cli/src", "python/src"];

/// Every `.rs` file under `dir`, sorted by path, tests' own files left out.
fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.expect("directory entry").path())
        .collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs")
            && p.file_name().is_some_and(|n| n != "tests.rs")
        {
            out.push(p);
        }
    }
}

/// The first paragraph of a file's `//!` comment, on one line, links turned to code.
fn first_paragraph(text: &str) -> String {
    let mut words = Vec::new();
    for line in text.lines().skip_while(|l| !l.starts_with("//!")) {
        let Some(rest) = line.strip_prefix("//!") else {
            break;
        };
        let rest = rest.trim();
        if (rest.is_empty() && !words.is_empty()) || rest.starts_with("```") {
            break;
        }
        if !rest.is_empty() {
            words.push(rest.to_string());
        }
    }
    words.join(" ").replace("[`", "`").replace("`]", "`")
}

/// One line for the table: the first sentence (two if the first is very short), cut at a
/// colon, semicolon or parenthesis when it runs long.
fn summary(paragraph: &str) -> String {
    let mut sentences = Vec::new();
    let mut start = 0;
    let bytes = paragraph.as_bytes();
    for (i, &b) in bytes.iter().enumerate() {
        if b == b'.' && (i + 1 == bytes.len() || bytes[i + 1] == b' ') {
            sentences.push(&paragraph[start..=i]);
            start = i + 1;
        }
    }
    if sentences.is_empty() {
        return paragraph.to_string();
    }
    let mut out = sentences[0].trim().to_string();
    if out.len() < 30 && sentences.len() > 1 {
        out = format!("{out} {}", sentences[1].trim());
    }
    if out.len() > 200 {
        for sep in [": ", "; ", " ("] {
            if let Some(i) = out.find(sep).filter(|&i| (40..200).contains(&i)) {
                out = format!("{}.", out[..i].trim_end_matches(','));
                break;
            }
        }
    }
    out
}

/// The generated part of the page.
fn table(root: &Path) -> String {
    let mut out = String::from(START);
    for dir in ROOTS {
        out.push_str(&format!(
            "\n### `{dir}/`\n\n| module | what it is |\n|---|---|\n"
        ));
        let mut files = Vec::new();
        rust_files(&root.join(dir), &mut files);
        for f in files {
            let text =
                std::fs::read_to_string(&f).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
            let name = f.strip_prefix(root.join(dir)).expect("under its root");
            out.push_str(&format!(
                "| `{}` | {} |\n",
                name.display(),
                summary(&first_paragraph(&text))
            ));
        }
    }
    out.push('\n');
    out.push_str(END);
    out
}

#[test]
fn internals_doc_lists_every_module_as_its_documentation_says() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let path = root.join(PAGE);
    let page = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let (Some(a), Some(b)) = (page.find(START), page.find(END)) else {
        panic!(
            "{PAGE} has no `{}` ... `{}` markers",
            START.trim(),
            END.trim()
        );
    };
    let want = table(&root);
    let have = &page[a..b + END.len()];
    let write = || {
        let new = format!("{}{want}{}", &page[..a], &page[b + END.len()..]);
        std::fs::write(&path, new).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    };
    super::support::generated_page(PAGE, have, &want, write, REMAKE);
}

#[test]
fn summary_is_the_first_sentence() {
    assert_eq!(summary("Cameras. More here."), "Cameras. More here.");
    assert_eq!(
        summary("The nodes rays walk, decoded to plain boxes. Then more."),
        "The nodes rays walk, decoded to plain boxes."
    );
    assert_eq!(
        first_paragraph("//! A [`Film`] of\n//! pixels.\n//!\n//! Rest."),
        "A `Film` of pixels."
    );
}
