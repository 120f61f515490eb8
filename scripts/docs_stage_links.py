#!/usr/bin/env python3
"""Makes the links a staged copy of docs/ holds into the rest of the repository work in the site.

Usage: docs_stage_links.py STAGED_DOCS REPO

The pages in docs/ link to files outside docs/ by relative paths that work when the Markdown is
read in the repository (on GitHub, say): ../benchmarks/RESULTS.md, ../../benchmarks/results/x.png.
mkdocs only knows the files under docs_dir, so for the site each such file is copied from REPO
into STAGED_DOCS/repo/<its path in REPO> and the link in the staged page rewritten to point at the
copy. Markdown files copied this way are processed in turn (their own relative links are resolved
in the folder they come from). A link to a file that does not exist in REPO is an error.
Links inside fenced code blocks and inline code are left alone.
"""
import os
import re
import shutil
import sys

LINK = re.compile(r'(!?\[[^\]]*\]\()([^)\s]+)((?:\s+"[^"]*")?\))')
FENCE = re.compile(r'^\s*(```|~~~)')
CODE_SPAN = re.compile(r'`[^`]*`')


def main():
    if len(sys.argv) != 3:
        print('usage: docs_stage_links.py STAGED_DOCS REPO', file=sys.stderr)
        return 2
    staged = os.path.realpath(sys.argv[1])
    repo = os.path.realpath(sys.argv[2])
    docs = os.path.join(repo, 'docs')
    errors = []
    copied = {}

    def copy_in(repo_path):
        """Copies REPO/repo_path into the staged tree once; returns the staged path."""
        rel = os.path.relpath(repo_path, repo)
        dest = os.path.join(staged, 'repo', rel)
        if rel not in copied:
            os.makedirs(os.path.dirname(dest), exist_ok=True)
            shutil.copyfile(repo_path, dest)
            copied[rel] = dest
            if dest.endswith('.md'):
                queue.append((dest, os.path.dirname(repo_path)))
        return dest

    def rewrite(staged_file, source_dir):
        """Rewrites the outside links of one staged page; source_dir is where it lives in REPO."""
        with open(staged_file, encoding='utf-8') as f:
            lines = f.read().split('\n')
        in_fence = False
        changed = False
        for i, line in enumerate(lines):
            if FENCE.match(line):
                in_fence = not in_fence
                continue
            if in_fence:
                continue
            spans = [m.span() for m in CODE_SPAN.finditer(line)]

            def fix(m):
                nonlocal changed
                if any(a <= m.start() < b for a, b in spans):
                    return m.group(0)
                target = m.group(2)
                if re.match(r'^[a-z][a-z0-9+.-]*:', target) or target.startswith(('#', '/')):
                    return m.group(0)
                path, _, frag = target.partition('#')
                if not path:
                    return m.group(0)
                resolved = os.path.normpath(os.path.join(source_dir, path))
                inside_docs = resolved == docs or resolved.startswith(docs + os.sep)
                if inside_docs and source_dir.startswith(docs):
                    return m.group(0)  # an ordinary link between pages: mkdocs checks it
                if not (resolved.startswith(repo + os.sep)):
                    errors.append(f'{staged_file}: {target}: leaves the repository')
                    return m.group(0)
                if os.path.isdir(resolved):
                    return m.group(0)  # a folder: no page to link to; left as written
                if not os.path.isfile(resolved):
                    errors.append(f'{os.path.relpath(staged_file, staged)}: {target}: '
                                  f'no such file {os.path.relpath(resolved, repo)}')
                    return m.group(0)
                dest = copy_in(resolved)
                new = os.path.relpath(dest, os.path.dirname(staged_file)).replace(os.sep, '/')
                changed = True
                return m.group(1) + new + ('#' + frag if frag else '') + m.group(3)

            lines[i] = LINK.sub(fix, line)
        if changed:
            with open(staged_file, 'w', encoding='utf-8') as f:
                f.write('\n'.join(lines))

    queue = []
    for root, _, files in os.walk(staged):
        if os.path.relpath(root, staged).split(os.sep)[0] == 'repo':
            continue
        for name in files:
            if name.endswith('.md'):
                page = os.path.join(root, name)
                queue.append((page, os.path.join(docs, os.path.relpath(root, staged))))
    while queue:
        page, source_dir = queue.pop()
        rewrite(page, os.path.normpath(source_dir))
    for e in errors:
        print(f'docs_stage_links: {e}', file=sys.stderr)
    print(f'docs_stage_links: {len(copied)} repository files copied into the site',
          file=sys.stderr)
    return 1 if errors else 0


if __name__ == '__main__':
    sys.exit(main())
