#!/usr/bin/env python3
"""The checks behind tests/docs/*.sh. Standard library only (Debian's /usr/bin/python3).

  docs_checks.py site SITE_DIR REPO PENUMBRA  built pages, links, anchors, pictures, examples
  docs_checks.py flags REPO PENUMBRA [BENCH]   the command reference against every --help
  docs_checks.py png FILE                      a PNG decoded: size, distinct colours, non-white share
  docs_checks.py dom-images DOM_FILE PAGE_FILE SITE_DIR   what the browser loaded (see browser test)

Each prints one line per failure ("FAIL: ...") and exits 1 when there is any.
"""
import html.parser
import json
import os
import re
import struct
import subprocess
import sys
import tempfile
import zlib

ACCELERATORS = ['embree', 'bvh', 'kdtree', 'grid', 'octree', 'bsp', 'brute']
failures = []


def fail(msg):
    if msg not in failures:
        failures.append(msg)
        print(f'FAIL: {msg}')


def done(what):
    if failures:
        print(f'{what}: {len(failures)} failure(s)')
        return 1
    print(f'{what}: ok')
    return 0


# ---------------------------------------------------------------------------------------------
# PNG decoding (8-bit, non-interlaced: what Penumbra, oiiotool and Chromium write)

def decode_png(path):
    """Returns (width, height, channels, rows) with rows a list of bytes; raises ValueError."""
    with open(path, 'rb') as f:
        data = f.read()
    if data[:8] != b'\x89PNG\r\n\x1a\n':
        raise ValueError('not a PNG (bad signature)')
    pos, idat, ihdr, ended = 8, [], None, False
    while pos + 8 <= len(data):
        length, kind = struct.unpack('>I4s', data[pos:pos + 8])
        chunk = data[pos + 8:pos + 8 + length]
        if len(chunk) != length:
            raise ValueError(f'truncated {kind!r} chunk')
        crc = struct.unpack('>I', data[pos + 8 + length:pos + 12 + length])[0]
        if zlib.crc32(kind + chunk) & 0xffffffff != crc:
            raise ValueError(f'bad CRC in {kind!r} chunk')
        if kind == b'IHDR':
            ihdr = struct.unpack('>IIBBBBB', chunk)
        elif kind == b'IDAT':
            idat.append(chunk)
        elif kind == b'IEND':
            ended = True
            break
        pos += 12 + length
    if ihdr is None or not ended:
        raise ValueError('no IHDR or no IEND chunk')
    width, height, depth, ctype, _, _, interlace = ihdr
    if width == 0 or height == 0:
        raise ValueError('zero width or height')
    channels = {0: 1, 2: 3, 4: 2, 6: 4}.get(ctype)
    if depth != 8 or channels is None or interlace:
        raise ValueError(f'unsupported PNG layout (depth {depth}, colour type {ctype}, interlace {interlace})')
    raw = zlib.decompress(b''.join(idat))
    stride = width * channels
    if len(raw) != height * (stride + 1):
        raise ValueError('pixel data of the wrong size')
    rows, prev = [], bytearray(stride)
    for y in range(height):
        ftype = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        if ftype == 1:
            for i in range(channels, stride):
                line[i] = (line[i] + line[i - channels]) & 0xff
        elif ftype == 2:
            for i in range(stride):
                line[i] = (line[i] + prev[i]) & 0xff
        elif ftype == 3:
            for i in range(stride):
                left = line[i - channels] if i >= channels else 0
                line[i] = (line[i] + ((left + prev[i]) >> 1)) & 0xff
        elif ftype == 4:
            for i in range(stride):
                a = line[i - channels] if i >= channels else 0
                b = prev[i]
                c = prev[i - channels] if i >= channels else 0
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                pred = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                line[i] = (line[i] + pred) & 0xff
        elif ftype != 0:
            raise ValueError(f'bad filter type {ftype} in row {y}')
        rows.append(bytes(line))
        prev = line
    return width, height, channels, rows


def png_stats(path):
    """(width, height, distinct colours, share of pixels that are not white)."""
    width, height, channels, rows = decode_png(path)
    colours = set()
    non_white = 0
    c = min(channels, 3)
    white = bytes([255] * c)
    for row in rows:
        for x in range(0, len(row), channels):
            px = row[x:x + c]
            colours.add(px)
            if px != white:
                non_white += 1
    return width, height, len(colours), non_white / float(width * height)


def is_svg(path):
    try:
        import xml.etree.ElementTree as ET
        return ET.parse(path).getroot().tag.endswith('svg')
    except Exception:
        return False


def check_picture(path, where):
    """A picture a page shows: a PNG that decodes, or an SVG that parses."""
    if not os.path.isfile(path):
        fail(f'{where}: picture {path} does not exist')
        return
    if os.path.getsize(path) == 0:
        fail(f'{where}: picture {path} is empty')
        return
    if path.endswith('.svg'):
        if not is_svg(path):
            fail(f'{where}: {path} is not an SVG document')
        return
    try:
        decode_png(path)
    except (ValueError, zlib.error) as e:
        fail(f'{where}: picture {path} is not a valid PNG: {e}')


# ---------------------------------------------------------------------------------------------
# The built site

class PageParser(html.parser.HTMLParser):
    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.ids, self.links, self.images, self.resources = set(), [], [], []

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if 'id' in a:
            self.ids.add(a['id'])
        if tag == 'a' and a.get('name'):
            self.ids.add(a['name'])
        if tag == 'a' and a.get('href'):
            self.links.append(a['href'])
        if tag == 'img' and a.get('src') is not None:
            self.images.append(a['src'])
        if tag == 'script' and a.get('src'):
            self.resources.append(a['src'])
        if tag == 'link' and a.get('href') and 'stylesheet' in (a.get('rel') or ''):
            self.resources.append(a['href'])


def parse_page(path):
    p = PageParser()
    with open(path, encoding='utf-8') as f:
        p.feed(f.read())
    return p


def is_external(url):
    return re.match(r'^[a-zA-Z][a-zA-Z0-9+.-]*:', url) is not None


def site_pages(site):
    for root, dirs, files in os.walk(site):
        dirs[:] = [d for d in dirs if d not in ('search',)]
        for name in files:
            if name.endswith('.html'):
                yield os.path.join(root, name)


def check_site(site, repo, penumbra):
    site = os.path.realpath(site)
    docs = os.path.join(repo, 'docs')
    # Every page of docs/ was built, and the ones the project promises are there.
    for root, _, files in os.walk(docs):
        for name in files:
            if name.endswith('.md'):
                rel = os.path.relpath(os.path.join(root, name), docs)
                page = os.path.join(site, rel[:-3] + '.html')
                if not os.path.isfile(page):
                    fail(f'docs/{rel} was not built into {os.path.relpath(page, site)}')
    for must in ['index.html', 'reference/commands.html', 'reference/formats.html',
                 'reference/gltf-support.html', 'reference/outputs-and-errors.html',
                 'reference/extensions/PENUMBRA_shapes.html',
                 'reference/extensions/PENUMBRA_procedural.html']:
        if not os.path.isfile(os.path.join(site, must)):
            fail(f'{must} is missing from the site')

    parsed = {}
    for page in site_pages(site):
        parsed[page] = parse_page(page)
    pictures = 0
    for page, p in parsed.items():
        rel = os.path.relpath(page, site)
        if rel in ('404.html', 'search.html'):
            continue
        for url in p.resources:
            if is_external(url) or url.startswith('//'):
                fail(f'{rel}: loads {url} from the network (the site must work offline)')
        for src in p.images:
            if is_external(src):
                fail(f'{rel}: picture {src} comes from the network')
                continue
            pictures += 1
            check_picture(os.path.normpath(os.path.join(os.path.dirname(page), src.split('#')[0])), rel)
        for href in p.links:
            if is_external(href) or href.startswith('mailto:'):
                continue
            path, _, frag = href.partition('#')
            target = page if not path else os.path.normpath(os.path.join(os.path.dirname(page), path))
            if path and path.endswith('/'):
                continue  # a folder (benchmarks/results/ from RESULTS.md): not a page
            if not os.path.exists(target):
                fail(f'{rel}: link {href}: {os.path.relpath(target, site)} does not exist')
                continue
            if frag and target.endswith('.html'):
                ids = parsed[target].ids if target in parsed else parse_page(target).ids
                if frag not in ids:
                    fail(f'{rel}: link {href}: no anchor #{frag} in {os.path.relpath(target, site)}')
    if pictures == 0:
        fail('no page shows a picture')

    # The README's links: relative files exist; links into docs/ land on built pages and anchors.
    readme = open(os.path.join(repo, 'README.md'), encoding='utf-8').read()
    readme = re.sub(r'```.*?```', '', readme, flags=re.S)
    for m in re.finditer(r'\]\(([^)\s]+)\)', readme):
        url = m.group(1)
        if is_external(url) or url.startswith('#'):
            continue
        path, _, frag = url.partition('#')
        target = os.path.normpath(os.path.join(repo, path))
        if not os.path.exists(target):
            fail(f'README.md: link {url}: {path} does not exist')
            continue
        if frag and target.startswith(docs + os.sep) and target.endswith('.md'):
            page = os.path.join(site, os.path.relpath(target, docs)[:-3] + '.html')
            if page in parsed and frag not in parsed[page].ids:
                fail(f'README.md: link {url}: no anchor #{frag} in the built page')

    # The extension pages: JSON blocks parse, complete glTF examples load, schemas hold them.
    ext_dir = os.path.join(docs, 'reference', 'extensions')
    for name in sorted(os.listdir(ext_dir)):
        if not name.endswith('.md'):
            continue
        text = open(os.path.join(ext_dir, name), encoding='utf-8').read()
        blocks = re.findall(r'```json\n(.*?)\n```', text, flags=re.S)
        docs_json, schema, examples = [], None, []
        for i, b in enumerate(blocks):
            try:
                j = json.loads(b)
            except ValueError as e:
                fail(f'{name}: JSON block {i + 1} does not parse: {e}')
                continue
            if isinstance(j, dict) and '$schema' in j:
                schema = j
            elif isinstance(j, dict) and 'asset' in j:
                examples.append(j)
            docs_json.append(j)
        if schema is None:
            fail(f'{name}: no JSON schema block')
        if not examples:
            fail(f'{name}: no complete glTF example')
        extension = name[:-3]
        for k, ex in enumerate(examples):
            with tempfile.NamedTemporaryFile('w', suffix='.gltf', delete=False) as f:
                json.dump(ex, f)
                tmp = f.name
            try:
                r = subprocess.run([penumbra, 'info', tmp], capture_output=True, text=True, timeout=60)
            finally:
                os.unlink(tmp)
            if r.returncode != 0:
                fail(f'{name}: example {k + 1}: penumbra info exits {r.returncode}: {r.stderr.strip()}')
            elif f'{extension} ' not in r.stdout or 'supported' not in r.stdout:
                fail(f'{name}: example {k + 1}: penumbra info does not report {extension}')
            try:
                import jsonschema  # optional: Debian's python3-jsonschema
            except ImportError:
                continue
            v = jsonschema.Draft202012Validator(schema)
            for owner in ('nodes', 'materials'):
                for idx, item in enumerate(ex.get(owner, [])):
                    obj = item.get('extensions', {}).get(extension)
                    if obj is not None:
                        for err in v.iter_errors(obj):
                            fail(f'{name}: example {k + 1}: {owner}[{idx}] against the schema: {err.message}')
    return done('docs site')


# ---------------------------------------------------------------------------------------------
# Flags: the command reference against every --help

OPTION_LINE = re.compile(r'^  (-{1,2}[A-Za-z0-9][\w-]*(?:,\s*-{1,2}[A-Za-z0-9][\w-]*)*)(.*)$')
FLAG = re.compile(r'(?<![\w-])(--?[A-Za-z][\w-]*)')


def run_help(argv):
    r = subprocess.run(argv + ['--help'], capture_output=True, text=True, timeout=60)
    if r.returncode != 0:
        fail(f'{" ".join(argv)} --help exits {r.returncode}')
    return r.stdout


def help_entries(text):
    """[(flags, description)] of every option a CLI11 help text lists."""
    entries, current = [], None
    for line in text.split('\n'):
        m = OPTION_LINE.match(line)
        if m:
            flags = [f.strip() for f in m.group(1).split(',')]
            current = (flags, [m.group(2)])
            entries.append(current)
        elif current is not None and line.startswith('    '):
            current[1].append(line)
        else:
            current = None
    return [(f, ' '.join(d)) for f, d in entries]


def subcommands(text):
    out, on = [], False
    for line in text.split('\n'):
        if line.startswith('Subcommands:'):
            on = True
            continue
        if on:
            m = re.match(r'^  ([a-z][\w-]*)\s', line)
            if m:
                out.append(m.group(1))
            elif line.strip() and not line.startswith('   '):
                on = False
    return out


def named_accelerators(description):
    return [a for a in ACCELERATORS if re.search(r'(?<![\w.])' + a + r'(?![\w.])', description)]


def reference_sections(path):
    """{'penumbra render': [flags listed in the first column of its option table], ...}"""
    sections, current = {}, None
    for line in open(path, encoding='utf-8'):
        line = line.rstrip('\n')
        m = re.match(r'^## (.+?)\s*$', line)
        if m:
            title = m.group(1)
            current = title if re.match(r'^penumbra(-[a-z]+)?( [a-z]+)*$', title) else None
            if current is not None:
                sections[current] = {'flags': [], 'rows': [], 'accel_rows': []}
            continue
        if current is None or not line.startswith('|'):
            continue
        cells = [c.strip() for c in re.split(r'(?<!\\)\|', line)[1:-1]]
        if not cells or set(cells[0]) <= set('-: '):
            continue
        first = cells[0]
        spans = re.findall(r'`([^`]*)`', first)
        flags = [f for s in spans for f in FLAG.findall(s)]
        if not flags:
            continue  # the header row, or a positional such as SCENES...
        sections[current]['flags'].extend(flags)
        sections[current]['rows'].append(line)
        if '--accel' in flags:
            sections[current]['accel_rows'].append(' '.join(cells[1:]))
    return sections


def check_flags(repo, penumbra, bench):
    ref = os.path.join(repo, 'docs', 'reference', 'commands.md')
    sections = reference_sections(ref)
    commands = {}  # title -> argv
    queue = [('penumbra', [penumbra])]
    while queue:
        title, argv = queue.pop(0)
        commands[title] = argv
        for sub in subcommands(run_help(argv)):
            queue.append((f'{title} {sub}', argv + [sub]))
    if bench:
        commands['penumbra-bench'] = [bench]
        scenegen = os.path.join(os.path.dirname(bench), 'penumbra-scenegen')
        if os.access(scenegen, os.X_OK):
            commands['penumbra-scenegen'] = [scenegen]
    checked_flags = 0
    for title, argv in commands.items():
        text = run_help(argv)
        entries = help_entries(text)
        help_flags = [f for flags, _ in entries for f in flags]
        for flags, desc in entries:
            named = named_accelerators(desc)
            if len(named) >= 2:
                missing = [a for a in ACCELERATORS if a not in named]
                if missing:
                    fail(f'{title} --help: {"/".join(flags)} lists structures but not '
                         f'{", ".join(missing)} (it names {", ".join(named)})')
        if title not in sections:
            fail(f'{title}: no "## {title}" section in docs/reference/commands.md')
            continue
        documented = sections[title]['flags']
        for f in help_flags:
            checked_flags += 1
            if f not in documented:
                fail(f'{title}: {f} is in --help but not in its section of docs/reference/commands.md')
        for f in sorted(set(documented)):
            if f not in help_flags:
                fail(f'{title}: docs/reference/commands.md lists {f}, which --help does not print')
        for row in sections[title]['accel_rows']:
            missing = [a for a in ACCELERATORS if a not in named_accelerators(row)]
            if missing:
                fail(f'{title}: the --accel row of docs/reference/commands.md does not name {", ".join(missing)}')
    for title in sections:
        if title not in commands:
            if title.startswith('penumbra-') and not bench:
                print(f'note: {title} not checked (no PENUMBRA_BENCH given)')
            else:
                fail(f'docs/reference/commands.md has a section "{title}", which is no command')
    print(f'checked {checked_flags} options of {len(commands)} commands')
    return done('docs flags')


# ---------------------------------------------------------------------------------------------
# What the browser loaded: the page's own report (see docs_browser_test.sh) and the files

def check_dom(dom_file, page_file, site, expect_pictures):
    text = open(dom_file, encoding='utf-8', errors='replace').read()
    m = re.search(r'data-penumbra-check="([^"]*)"', text)
    rel = os.path.relpath(page_file, site)
    if not m:
        fail(f'{rel}: the page never reported its load (no data-penumbra-check in the DOM)')
        return done(f'browser {rel}')
    report = json.loads(html.unescape(m.group(1)))
    if report.get('stylesheets', 0) < 1:
        fail(f'{rel}: no stylesheet loaded')
    images = report.get('images', [])
    if expect_pictures and not images:
        fail(f'{rel}: the page shows no picture')
    for src, complete, w, h in images:
        if not complete or w == 0 or h == 0:
            fail(f'{rel}: picture {src} was not loaded (complete={complete}, {w}x{h})')
        if is_external(src):
            fail(f'{rel}: picture {src} comes from the network')
            continue
        check_picture(os.path.normpath(os.path.join(os.path.dirname(page_file), src)), rel)
    print(f'{rel}: {len(images)} picture(s) loaded, {report.get("stylesheets")} stylesheet(s)')
    return done(f'browser {rel}')


def main():
    if len(sys.argv) < 2:
        print(__doc__, file=sys.stderr)
        return 2
    cmd, args = sys.argv[1], sys.argv[2:]
    if cmd == 'site' and len(args) == 3:
        return check_site(*args)
    if cmd == 'flags' and len(args) in (2, 3):
        return check_flags(args[0], args[1], args[2] if len(args) == 3 else None)
    if cmd == 'png' and len(args) == 1:
        try:
            w, h, colours, share = png_stats(args[0])
        except (OSError, ValueError, zlib.error) as e:
            print(f'FAIL: {args[0]}: {e}')
            return 1
        print(f'{w} {h} {colours} {share:.4f}')
        return 0
    if cmd == 'dom-images' and len(args) == 4:
        return check_dom(args[0], args[1], args[2], args[3] == '1')
    print(__doc__, file=sys.stderr)
    return 2


if __name__ == '__main__':
    sys.exit(main())
