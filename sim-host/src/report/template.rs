//! Prose kept in Markdown files beside the command that fills it in, so that it reads as prose
//! rather than as string literals.
//!
//! A template is a sequence of blocks. A block opens with a line `<!-- name -->` and runs to the
//! next such line; whatever comes before the first block is a note to the reader of the file.
//! A block's paragraphs are separated by blank lines, and each becomes one line of the output:
//! the file is wrapped for reading, a generated document keeps one line per paragraph. `{key}`
//! stands for a value the command supplies.

/// The paragraphs of block `name` of `template` (none when it has no such block), each on one
/// line, with every `{key}` of `values` replaced by its value; a `{...}` that names no value is
/// kept as written.
pub fn paragraphs(template: &str, name: &str, values: &[(&str, &str)]) -> Vec<String> {
    let marker = format!("<!-- {name} -->");
    let mut lines = template.lines().skip_while(|l| l.trim_end() != marker);
    if lines.next().is_none() {
        return Vec::new();
    }
    let body: Vec<&str> = lines.take_while(|l| !is_marker(l)).collect();
    body.split(|l| l.trim().is_empty())
        .filter(|p| !p.is_empty())
        .map(|p| fill(&p.join(" "), values))
        .collect()
}

/// Block `name` of `template` filled in, its paragraphs separated by blank lines.
pub fn block(template: &str, name: &str, values: &[(&str, &str)]) -> String {
    paragraphs(template, name, values).join("\n\n")
}

/// A line that opens a block: `<!-- name -->` with a name of lowercase letters, digits and `_`.
fn is_marker(line: &str) -> bool {
    line.trim_end()
        .strip_prefix("<!-- ")
        .and_then(|l| l.strip_suffix(" -->"))
        .is_some_and(|n| {
            !n.is_empty()
                && n.chars()
                    .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_')
        })
}

/// `text` with every `{key}` of `values` replaced, in one pass (a value is never searched for
/// keys itself).
fn fill(text: &str, values: &[(&str, &str)]) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(i) = rest.find('{') {
        out.push_str(&rest[..i]);
        let after = &rest[i + 1..];
        let value = after.find('}').and_then(|j| {
            let key = &after[..j];
            values.iter().find(|(k, _)| *k == key).map(|(_, v)| (v, j))
        });
        match value {
            Some((v, j)) => {
                out.push_str(v);
                rest = &after[j + 1..];
            }
            None => {
                out.push('{');
                rest = after;
            }
        }
    }
    out.push_str(rest);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    const T: &str = "<!-- A note on the file,\nover two lines. -->\n\n\
                     <!-- one -->\nFirst {x} of\nthe block.\n\nSecond {y}, {unknown} kept.\n\
                     <!-- two -->\n\n- **Item** {x}\n";

    #[test]
    fn blocks_are_unwrapped_and_filled() {
        let v = [("x", "1 {y}"), ("y", "2")];
        assert_eq!(
            paragraphs(T, "one", &v),
            ["First 1 {y} of the block.", "Second 2, {unknown} kept."]
        );
        assert_eq!(block(T, "two", &v), "- **Item** 1 {y}");
        assert!(paragraphs(T, "three", &v).is_empty());
    }
}
