//! Every relative link in README.md, CONTRIBUTING.md and docs/*.md resolves: the file or
//! folder exists, and a `file.md#anchor` link names a heading of that file (GitHub's slug:
//! lowercase, punctuation other than '-', '_' and ' ' removed, spaces to '-', a repeated
//! heading numbered `-1`, `-2`, ...). Web links (`http://`, `https://`, `mailto:`) and
//! links inside fenced code blocks or inline code are not checked.

use std::collections::BTreeSet;
use std::fs;
use std::path::{Path, PathBuf};

/// The workspace root: two folders above this crate's manifest.
fn workspace_root() -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    fs::canonicalize(&root).unwrap_or(root)
}

/// The Markdown files whose links are checked, relative to the workspace root.
fn checked_files(root: &Path) -> Vec<PathBuf> {
    let mut files = vec![root.join("README.md"), root.join("CONTRIBUTING.md")];
    let mut docs: Vec<PathBuf> = fs::read_dir(root.join("docs"))
        .expect("docs/ is readable")
        .map(|entry| entry.expect("docs/ entry").path())
        .filter(|path| path.extension().is_some_and(|ext| ext == "md"))
        .collect();
    docs.sort();
    files.extend(docs);
    files
}

/// The lines of `text` outside fenced code blocks (``` or ~~~), with their 1-based numbers.
fn prose_lines(text: &str) -> Vec<(usize, &str)> {
    let mut fence: Option<&str> = None;
    let mut lines = Vec::new();
    for (index, line) in text.lines().enumerate() {
        let trimmed = line.trim_start();
        let marker = ["```", "~~~"]
            .into_iter()
            .find(|marker| trimmed.starts_with(marker));
        match (fence, marker) {
            (None, Some(marker)) => fence = Some(marker),
            (Some(open), Some(marker)) if open == marker => fence = None,
            (None, None) => lines.push((index + 1, line)),
            _ => {}
        }
    }
    lines
}

/// `line` with the contents of inline code spans blanked out (the backticks kept).
fn without_code_spans(line: &str) -> String {
    let mut out = String::with_capacity(line.len());
    let mut in_code = false;
    for c in line.chars() {
        if c == '`' {
            in_code = !in_code;
            out.push(c);
        } else if in_code {
            out.push(' ');
        } else {
            out.push(c);
        }
    }
    out
}

/// The targets of the inline links `[text](target)` on one line of prose.
fn link_targets(line: &str) -> Vec<String> {
    let line = without_code_spans(line);
    let mut targets = Vec::new();
    let mut rest = line.as_str();
    while let Some(start) = rest.find("](") {
        let after = &rest[start + 2..];
        let mut depth = 1usize;
        let mut end = None;
        for (i, c) in after.char_indices() {
            match c {
                '(' => depth += 1,
                ')' => {
                    depth -= 1;
                    if depth == 0 {
                        end = Some(i);
                        break;
                    }
                }
                _ => {}
            }
        }
        let Some(end) = end else { break };
        let target = after[..end].trim();
        // A title after the target ("file.md \"title\"") is not part of the path.
        let target = target.split_whitespace().next().unwrap_or("");
        let target = target.trim_start_matches('<').trim_end_matches('>');
        targets.push(target.to_string());
        rest = &after[end..];
    }
    targets
}

/// GitHub's anchor for a heading's text.
fn slug(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter(|c| c.is_alphanumeric() || *c == '-' || *c == '_' || *c == ' ')
        .map(|c| if c == ' ' { '-' } else { c })
        .collect()
}

/// Every anchor the headings of a Markdown text give (ATX headings outside code blocks).
fn anchors(text: &str) -> BTreeSet<String> {
    let mut seen: BTreeSet<String> = BTreeSet::new();
    for (_, line) in prose_lines(text) {
        let trimmed = line.trim_start();
        let hashes = trimmed.chars().take_while(|c| *c == '#').count();
        if hashes == 0 || hashes > 6 || !trimmed[hashes..].starts_with(' ') {
            continue;
        }
        let title = trimmed[hashes..].trim().trim_end_matches('#').trim();
        let base = slug(title);
        let mut anchor = base.clone();
        let mut n = 1;
        while seen.contains(&anchor) {
            anchor = format!("{base}-{n}");
            n += 1;
        }
        seen.insert(anchor);
    }
    seen
}

/// What is wrong with one link target found in `file`, if anything.
fn check_target(file: &Path, target: &str) -> Option<String> {
    let lower = target.to_lowercase();
    if target.is_empty() {
        return Some("empty link".to_string());
    }
    if lower.starts_with("http://") || lower.starts_with("https://") || lower.starts_with("mailto:")
    {
        return None;
    }
    let (path_part, anchor) = match target.split_once('#') {
        Some((path, anchor)) => (path, Some(anchor)),
        None => (target, None),
    };
    let linked = if path_part.is_empty() {
        file.to_path_buf()
    } else {
        file.parent().expect("a file has a folder").join(path_part)
    };
    if !linked.exists() {
        return Some(format!("{target}: {} does not exist", linked.display()));
    }
    let anchor = anchor?;
    if linked.extension().is_none_or(|ext| ext != "md") {
        return Some(format!(
            "{target}: an anchor into a file that is not Markdown"
        ));
    }
    let text = fs::read_to_string(&linked).expect("linked Markdown is readable");
    if anchors(&text).contains(&anchor.to_lowercase()) {
        None
    } else {
        Some(format!(
            "{target}: no heading of {} has the anchor #{anchor}",
            linked.display()
        ))
    }
}

/// Every broken link of the given Markdown text, as "file:line: problem".
fn broken_links(file: &Path, text: &str, checked: &mut usize) -> Vec<String> {
    let mut broken = Vec::new();
    for (number, line) in prose_lines(text) {
        for target in link_targets(line) {
            *checked += 1;
            if let Some(problem) = check_target(file, &target) {
                broken.push(format!("{}:{number}: {problem}", file.display()));
            }
        }
    }
    broken
}

#[test]
fn every_relative_link_in_the_docs_resolves() {
    let root = workspace_root();
    let mut checked = 0;
    let mut broken = Vec::new();
    for file in checked_files(&root) {
        let text = fs::read_to_string(&file)
            .unwrap_or_else(|e| panic!("{} is readable: {e}", file.display()));
        broken.extend(broken_links(&file, &text, &mut checked));
    }
    assert!(
        checked > 20,
        "only {checked} links found: is the parser broken?"
    );
    assert!(
        broken.is_empty(),
        "{} broken link(s):\n{}",
        broken.len(),
        broken.join("\n")
    );
}

#[test]
fn slugs_follow_github() {
    assert_eq!(slug("1. Baseline"), "1-baseline");
    assert_eq!(slug("Turns, rest to rest"), "turns-rest-to-rest");
    assert_eq!(slug("`config.correction`"), "configcorrection");
    assert_eq!(
        slug("ROS 2 bags (`sensor_msgs/msg/Imu`)"),
        "ros-2-bags-sensor_msgsmsgimu"
    );
    let text = "# A\n```\n# not a heading\n```\n## A\n### Why: the choice\n";
    let found = anchors(text);
    let expected: BTreeSet<String> = ["a", "a-1", "why-the-choice"]
        .into_iter()
        .map(String::from)
        .collect();
    assert_eq!(found, expected);
}

#[test]
fn a_broken_link_is_found() {
    let root = workspace_root();
    let file = root.join("README.md");
    let text = "See [the model](docs/model-file.md#no-such-heading), [gone](docs/gone.md), \
                [web](https://example.org/x) and `[code](docs/not-checked.md)`.\n\
                ```\n[fenced](docs/not-checked-either.md)\n```\n";
    let mut checked = 0;
    let broken = broken_links(&file, text, &mut checked);
    assert_eq!(checked, 3, "{broken:?}");
    assert_eq!(broken.len(), 2, "{broken:?}");
    assert!(broken[0].contains("no-such-heading"), "{broken:?}");
    assert!(broken[1].contains("gone.md"), "{broken:?}");
}
