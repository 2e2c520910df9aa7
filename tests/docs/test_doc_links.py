# SPDX-License-Identifier: Apache-2.0
"""Every relative link of the repository's Markdown pages (README.md,
CONTRIBUTING.md, CHANGELOG.md, docs/**.md) leads somewhere: the file or
folder it names exists, and an anchor (`page.md#heading`, `#heading`)
names a heading of that page, by GitHub's rule for heading anchors
(lower case; letters, digits, spaces, '-' and '_' kept, the rest dropped;
spaces become '-'; a repeated heading gets -1, -2, ...). External links
(http, https, mailto) are not followed. Links inside code spans and
fenced code blocks are not links and are skipped.

Exits 1 listing each broken link as page:line: target. Then it shows that
it can fail: a copy of one page with one link's anchor changed, and one
with a link's file renamed, must each be reported.

Usage: test_doc_links.py [--root DIR]"""
import argparse
import os
import re
import sys
import tempfile
import shutil

LINK = re.compile(r"!?\[(?:[^\[\]]|\[[^\]]*\])*\]\(([^()\s]+(?:\([^()]*\))?[^()\s]*)(?:\s+\"[^\"]*\")?\)")
HEADING = re.compile(r"^(#{1,6})\s+(.*?)\s*#*\s*$")
FENCE = re.compile(r"^\s*(```|~~~)")
CODE_SPAN = re.compile(r"(`+)(.+?)\1")


def pages(root):
    """The Markdown pages checked, as paths relative to root."""
    out = [p for p in ("README.md", "CONTRIBUTING.md", "CHANGELOG.md")
           if os.path.isfile(os.path.join(root, p))]
    for d, _, files in os.walk(os.path.join(root, "docs")):
        out += [os.path.relpath(os.path.join(d, f), root)
                for f in sorted(files) if f.endswith(".md")]
    return sorted(out)


def prose_lines(text):
    """(line number, line) outside fenced code, code spans blanked."""
    fenced = False
    for n, line in enumerate(text.splitlines(), 1):
        if FENCE.match(line):
            fenced = not fenced
            continue
        if not fenced:
            yield n, CODE_SPAN.sub(lambda m: " " * len(m.group(0)), line)


def slug(heading):
    """GitHub's anchor of a heading's text."""
    text = re.sub(r"`", "", heading)
    text = re.sub(r"!?\[([^\]]*)\]\([^)]*\)", r"\1", text)  # a link: its text
    text = re.sub(r"<[^>]+>", "", text)
    text = text.strip().lower()
    text = "".join(c for c in text if c.isalnum() or c in " -_")
    return text.replace(" ", "-")


def anchors(path):
    """Every heading anchor of a Markdown file."""
    seen = {}
    out = set()
    with open(path, encoding="utf-8") as f:
        text = f.read()
    fenced = False
    for line in text.splitlines():
        if FENCE.match(line):
            fenced = not fenced
            continue
        m = None if fenced else HEADING.match(line)
        if not m:
            continue
        s = slug(m.group(2))
        k = seen.get(s, 0)
        seen[s] = k + 1
        out.add(s if k == 0 else "%s-%d" % (s, k))
    return out


def links(root):
    """(page, line, target) of every relative link of the pages."""
    for page in pages(root):
        with open(os.path.join(root, page), encoding="utf-8") as f:
            text = f.read()
        for n, line in prose_lines(text):
            for m in LINK.finditer(line):
                if not re.match(r"^[a-z][a-z0-9+.-]*:", m.group(1)):
                    yield page, n, m.group(1)  # not http:, https:, mailto:


def broken(root):
    """[(page, line, target)] of the links that lead nowhere."""
    cache = {}
    bad = []
    for page, n, target in links(root):
        path, _, anchor = target.partition("#")
        if path:
            full = os.path.normpath(os.path.join(root, os.path.dirname(page), path))
            if not os.path.exists(full):
                bad.append((page, n, target))
                continue
        else:
            full = os.path.join(root, page)
        if anchor and full.endswith(".md") and os.path.isfile(full):
            if full not in cache:
                cache[full] = anchors(full)
            if anchor.lower() not in cache[full]:
                bad.append((page, n, target))
    return bad


def first_link(root, with_anchor):
    """(page, target) of the first relative link to a .md page, with or
    without an anchor, for the self-test."""
    for page, _, t in links(root):
        p, _, a = t.partition("#")
        if p.endswith(".md") and bool(a) == with_anchor:
            return page, t
    return None


def bites(root):
    """Each of two broken copies must be reported: an anchor changed, a
    file name changed."""
    ok = True
    for with_anchor, spoil in ((True, lambda t: t + "-no-such-heading"),
                               (False, lambda t: t[:-3] + "-no-such-page.md")):
        found = first_link(root, with_anchor)
        if found is None:
            print("self-test: no link %s an anchor to spoil" % ("with" if with_anchor else "without"))
            ok = False
            continue
        page, target = found
        with tempfile.TemporaryDirectory() as tmp:
            for p in pages(root):
                os.makedirs(os.path.dirname(os.path.join(tmp, p)) or tmp, exist_ok=True)
                shutil.copy(os.path.join(root, p), os.path.join(tmp, p))
            # the files the links name (not only pages) must exist in the copy
            for d in ("docs",):
                for dd, _, files in os.walk(os.path.join(root, d)):
                    for f in files:
                        src = os.path.join(dd, f)
                        dst = os.path.join(tmp, os.path.relpath(src, root))
                        if not os.path.exists(dst):
                            os.makedirs(os.path.dirname(dst), exist_ok=True)
                            os.symlink(src, dst)
            for top in os.listdir(root):
                if not os.path.exists(os.path.join(tmp, top)):
                    os.symlink(os.path.join(root, top), os.path.join(tmp, top))
            path = os.path.join(tmp, page)
            with open(path, encoding="utf-8") as f:
                text = f.read()
            with open(path, "w", encoding="utf-8") as f:
                f.write(text.replace("(" + target + ")", "(" + spoil(target) + ")", 1))
            if not any(b[0] == page for b in broken(tmp)):
                print("self-test: %s with %s spoilt was not reported" % (page, target))
                ok = False
    return ok


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    here = os.path.dirname(os.path.abspath(__file__))
    ap.add_argument("--root", default=os.path.dirname(os.path.dirname(here)))
    args = ap.parse_args()
    bad = broken(args.root)
    for page, n, target in bad:
        print("%s:%d: %s leads nowhere" % (page, n, target))
    n_pages = len(pages(args.root))
    if bad:
        print("doc_links: %d broken links in %d pages" % (len(bad), n_pages))
        return 1
    if not bites(args.root):
        return 1
    print("doc_links: every relative link of %d pages leads somewhere" % n_pages)
    return 0


if __name__ == "__main__":
    sys.exit(main())
