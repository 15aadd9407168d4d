#!/usr/bin/env python3
"""The docs.links test: every link of README.md and docs/**/*.md to a local
file resolves, and so does its #anchor (a heading of the target, slugged as
GitHub does); every docs page is linked from the README, and every tool of
apps/CMakeLists.txt has a row in the README's tool table that links to its
page; the pictures in docs/img stay small.

Usage: check_doc_links.py SOURCE_DIR. Exit 0 when all holds; 1 with one line
per problem (file:line: what) otherwise. Web links are not fetched.
"""
import os
import re
import sys

LINK = re.compile(r'!?\[((?:[^\[\]]|\[[^\]]*\])*)\]\(\s*<?([^)\s>]+)>?(?:\s+"[^"]*")?\s*\)')
REFDEF = re.compile(r'^\s{0,3}\[[^\]]+\]:\s*<?(\S+?)>?(?:\s+.*)?$')
HEADING = re.compile(r'^\s{0,3}(#{1,6})\s+(.*?)\s*#*\s*$')
MAX_IMAGE_BYTES = 150 * 1024   # README pictures: readable, and cheap to clone


def strip_code(line):
    """Blanks inline code spans, so that `[a](b)` inside backticks is not a link."""
    return re.sub(r'(`+)(.+?)\1', lambda m: ' ' * len(m.group(0)), line)


def lines_outside_fences(text):
    fence = None
    for number, line in enumerate(text.split('\n'), 1):
        m = re.match(r'^\s{0,3}(`{3,}|~{3,})', line)
        if m:
            if fence is None:
                fence = m.group(1)[0] * len(m.group(1))
            elif m.group(1).startswith(fence):
                fence = None
            continue
        if fence is None:
            yield number, line


def slug(heading):
    """GitHub's anchor of a heading: the rendered text (link text, no
    backticks or emphasis marks), lower case, punctuation dropped, spaces as
    hyphens."""
    text = LINK.sub(lambda m: m.group(1), heading)
    text = re.sub(r'[`*]', '', text).strip().lower()
    text = re.sub(r'[^\w\- ]', '', text)
    return text.replace(' ', '-')


def anchors(path, cache={}):
    if path not in cache:
        seen, result = {}, set()
        with open(path, encoding='utf-8') as f:
            for _, line in lines_outside_fences(f.read()):
                m = HEADING.match(line)
                if m:
                    s = slug(m.group(2))
                    n = seen.get(s, 0)
                    seen[s] = n + 1
                    result.add(s if n == 0 else f'{s}-{n}')
        cache[path] = result
    return cache[path]


def links(path):
    with open(path, encoding='utf-8') as f:
        text = f.read()
    for number, line in lines_outside_fences(text):
        plain = strip_code(line)
        for m in LINK.finditer(plain):
            yield number, m.group(2)
        m = REFDEF.match(plain)
        if m:
            yield number, m.group(1)


def main(root):
    problems = []
    pages = [os.path.join(root, 'README.md')]
    for d, _, files in os.walk(os.path.join(root, 'docs')):
        pages += [os.path.join(d, f) for f in sorted(files) if f.endswith('.md')]
    readme_targets = set()
    for page in pages:
        rel = os.path.relpath(page, root)
        for number, target in links(page):
            if re.match(r'^[a-z][a-z0-9+.-]*:', target):      # http:, https:, mailto:
                continue
            file_part, _, anchor = target.partition('#')
            dest = os.path.normpath(os.path.join(os.path.dirname(page), file_part)) if file_part else page
            if not os.path.exists(dest):
                problems.append(f'{rel}:{number}: link to {target}: {os.path.relpath(dest, root)} does not exist')
                continue
            if page == pages[0]:
                readme_targets.add(os.path.relpath(dest, root))
            if anchor and dest.endswith('.md') and anchor not in anchors(dest):
                problems.append(f'{rel}:{number}: link to {target}: no heading with the anchor #{anchor} '
                                f'in {os.path.relpath(dest, root)}')
    for page in pages[1:]:
        rel = os.path.relpath(page, root)
        if rel not in readme_targets:
            problems.append(f'README.md: does not link {rel}')
    # Every tool has a row in the README's table, linking to a docs page.
    with open(os.path.join(root, 'apps', 'CMakeLists.txt'), encoding='utf-8') as f:
        tools = re.findall(r'^\s*robomach_add_app\(\s*([a-z0-9-]+)', f.read(), re.M)
    with open(pages[0], encoding='utf-8') as f:
        rows = [l for l in f.read().split('\n') if l.startswith('|')]
    for tool in tools:
        if not any(l.startswith(f'| `{tool}`') and '](docs/' in l for l in rows):
            problems.append(f'README.md: the tool table has no row for `{tool}` with a link to its docs page')
    if not tools:
        problems.append('apps/CMakeLists.txt: no robomach_add_app found (has the pattern changed?)')
    img = os.path.join(root, 'docs', 'img')
    for f in sorted(os.listdir(img)) if os.path.isdir(img) else []:
        size = os.path.getsize(os.path.join(img, f))
        if size > MAX_IMAGE_BYTES:
            problems.append(f'docs/img/{f}: {size} bytes, above {MAX_IMAGE_BYTES} '
                            '(scripts/recompress-png.py shrinks a plot without changing a pixel)')
    for p in problems:
        print(p)
    print(f'docs.links: {len(pages)} pages, {len(tools)} tools, {len(problems)} problem(s)')
    return 1 if problems else 0


if __name__ == '__main__':
    if len(sys.argv) != 2:
        sys.exit('usage: check_doc_links.py SOURCE_DIR')
    sys.exit(main(sys.argv[1]))
