#!/usr/bin/env python3
"""Every reference into the documentation resolves, so that renaming or moving a section
cannot leave a dangling pointer behind:
- Markdown links of README.md and doc/*.md: the file exists, and the #anchor is the
  GitHub anchor of one of its headings (lower case, punctuation dropped, spaces as hyphens,
  -1, -2 ... for repeated headings);
- references written as text anywhere in the sources, decks, tests and scripts:
  `doc/NAME.md, "Title"` names a heading of that file or a paragraph that opens with
  **Title**, and `doc/NAME.md section 6.2` (or `doc/NAME.md 6.2`) a heading numbered 6.2.
Usage (ctest does this): check_doc_links.py ROOT. Exit 1 with the file and the reference of
each one that does not resolve."""
import pathlib
import re
import sys

FOLDERS = ["doc", "src", "tests", "bench", "postproc", "scripts", "input", ".ci"]
SUFFIXES = {".md", ".f90", ".fypp", ".pf", ".py", ".dat", ".cmake", ".txt", ".sh", ".slurm"}
TEXT_REF = re.compile(
    r'doc/([a-z_]+\.md),?\s+(?:"([^"]+)"|(?:section\s+)?([0-9]+(?:\.[0-9]+)*)\b)')
# a line break inside a reference, with the comment marker of the next line
BREAK = re.compile(r"[ \t]*\n[ \t]*(?:!>?|#|//)?[ \t]*")


def headings(path):
    """The headings of a Markdown file, outside code fences."""
    out, fence = [], False
    for line in path.read_text(encoding="utf-8").split("\n"):
        if line.startswith("```"):
            fence = not fence
        elif not fence and re.match(r"#{1,6}\s", line):
            out.append(line.lstrip("#").strip())
    return out


def anchors(path):
    """GitHub's anchors of the headings of a Markdown file."""
    out, seen = set(), {}
    for heading in headings(path):
        text = re.sub(r"`([^`]*)`", r"\1", heading)
        text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", text)
        slug = re.sub(r"[^\w\- ]", "", text.lower()).replace(" ", "-")
        count = seen.get(slug, 0)
        seen[slug] = count + 1
        out.add(slug if count == 0 else f"{slug}-{count}")
    return out


def titled(path, title):
    """True when a heading of the file contains the title, or a paragraph opens with it in bold."""
    title = title.lower()
    if any(title in h.lower() for h in headings(path)):
        return True
    text = path.read_text(encoding="utf-8").lower()
    return re.search(r"(^|\n)\s*(- )?\*\*" + re.escape(title), text) is not None


def markdown_links(root, path):
    bad = []
    text = re.sub(r"```.*?```", "", path.read_text(encoding="utf-8"), flags=re.S)
    for m in re.finditer(r"\]\(([^)\s]+)\)", text):
        link = m.group(1)
        if re.match(r"[a-z]+:", link):
            continue  # web addresses are not checked: CI has no network
        file, _, fragment = link.partition("#")
        target = (path.parent / file) if file else path
        if not target.exists():
            bad.append(f"{path.relative_to(root)}: no file {link}")
        elif fragment and target.suffix == ".md" and fragment not in anchors(target):
            bad.append(f"{path.relative_to(root)}: no heading for the anchor {link}")
    return bad


def text_references(root, path):
    bad = []
    text = BREAK.sub(" ", path.read_text(encoding="utf-8", errors="replace"))
    for m in TEXT_REF.finditer(text):
        target = root / "doc" / m.group(1)
        if not target.exists():
            bad.append(f"{path.relative_to(root)}: no file in {m.group(0)}")
        elif m.group(2) and not titled(target, m.group(2)):
            bad.append(f"{path.relative_to(root)}: no section {m.group(0)}")
        elif m.group(3) and not any(re.match(re.escape(m.group(3)) + r"[ .]", h)
                                    for h in headings(target)):
            bad.append(f"{path.relative_to(root)}: no section {m.group(0)}")
    return bad


def main():
    root = pathlib.Path(sys.argv[1])
    markdown = [root / "README.md"] + sorted((root / "doc").glob("*.md"))
    texts = [root / "README.md"]
    for folder in FOLDERS:
        texts += sorted(p for p in (root / folder).rglob("*")
                        if p.is_file() and p.suffix in SUFFIXES)
    bad = [b for p in markdown for b in markdown_links(root, p)]
    bad += [b for p in texts for b in text_references(root, p)]
    for b in bad:
        print(b)
    print(f"{len(markdown)} Markdown files and {len(texts)} files read, {len(bad)} references "
          "that do not resolve")
    return 1 if bad or len(texts) < 2 else 0


if __name__ == "__main__":
    sys.exit(main())
