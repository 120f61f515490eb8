#!/usr/bin/env bash
# The built site in a real browser: headless Chromium opens the home page, the command reference
# and the AOV guide from disk (file://), each screenshot must show something (more than one
# colour, not all white), and every picture on the page must have been loaded and decoded by the
# browser (the page copies get a small script that records each <img>'s naturalWidth on load;
# --dump-dom reads it back) and be a valid PNG or SVG in the site. Chromium runs in a temporary
# HOME and profile, removed afterwards, under `timeout 60`.
# Usage: docs_browser_test.sh SITE_DIR (a site built by scripts/docs.sh). Exit 77 without chromium.
set -u
if [ $# -ne 1 ]; then echo "usage: docs_browser_test.sh SITE_DIR" >&2; exit 2; fi
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
site="$1"
browser=""
for c in chromium chromium-browser google-chrome; do
  if command -v "$c" >/dev/null; then browser="$c"; break; fi
done
if [ -z "$browser" ]; then
  echo "SKIP: chromium not found (scripts/install-deps.sh --test installs it)"
  exit 77
fi
if [ ! -f "$site/index.html" ]; then
  # Without mkdocs the build check was skipped and there is no site to look at.
  if ! command -v mkdocs >/dev/null; then echo "SKIP: no site at $site (mkdocs not found to build it)"; exit 77; fi
  echo "FAIL: $site/index.html does not exist (build the site first: tests/docs/docs_build_test.sh)"
  exit 1
fi

tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
cp -r "$site" "$tmp/site"
site="$(realpath "$tmp/site")"
mkdir -p "$tmp/home"
fails=0

chrome() {
  HOME="$tmp/home" timeout 60 "$browser" --headless --no-sandbox --disable-gpu --no-first-run \
    --user-data-dir="$tmp/profile" --hide-scrollbars "$@" 2>>"$tmp/chromium.log"
}

# PAGE EXPECT_PICTURES: screenshot and DOM check of one page of the copied site.
check_page() {
  local page="$1" pictures="$2" name shot dom stats
  name="$(echo "$page" | tr '/.' '__')"
  shot="$tmp/$name.png"; dom="$tmp/$name.dom.html"
  if ! chrome --screenshot="$shot" --window-size=1200,900 "file://$site/$page" >/dev/null \
     || [ ! -s "$shot" ]; then
    echo "FAIL: $page: no screenshot (chromium: $(tail -3 "$tmp/chromium.log"))"
    fails=$((fails + 1)); return
  fi
  if ! stats="$(python3 "$here/docs_checks.py" png "$shot")"; then
    echo "$stats"; fails=$((fails + 1)); return
  fi
  read -r w h colours share <<<"$stats"
  if [ "$colours" -le 1 ] || python3 -c "import sys; sys.exit(0 if float('$share') < 0.005 else 1)"; then
    echo "FAIL: $page: the screenshot is blank ($colours colours, ${share} of it not white)"
    fails=$((fails + 1))
  else
    echo "$page: screenshot ${w}x${h}, $colours colours, ${share} not white"
  fi
  # The page reports what it loaded into its own DOM once the load event has fired.
  python3 - "$site/$page" <<'PY'
import sys
p = sys.argv[1]
s = open(p, encoding='utf-8').read()
probe = ('<script>window.addEventListener("load",function(){document.body.setAttribute('
         '"data-penumbra-check",JSON.stringify({stylesheets:document.styleSheets.length,'
         'images:Array.from(document.images).map(function(i){return [i.getAttribute("src"),'
         'i.complete,i.naturalWidth,i.naturalHeight]})}))});</script>')
i = s.rfind('</body>')
open(p, 'w', encoding='utf-8').write(s[:i] + probe + s[i:] if i >= 0 else s + probe)
PY
  if ! chrome --virtual-time-budget=10000 --dump-dom "file://$site/$page" >"$dom"; then
    echo "FAIL: $page: chromium --dump-dom failed or timed out"
    fails=$((fails + 1)); return
  fi
  python3 "$here/docs_checks.py" dom-images "$dom" "$site/$page" "$site" "$pictures" || fails=$((fails + 1))
}

start=$SECONDS
check_page index.html 1
check_page reference/commands.html 0
check_page guide/aovs-and-compositing.html 1
echo "docs browser: $((SECONDS - start)) s"
if [ "$fails" -ne 0 ]; then echo "docs browser: $fails page(s) failed"; exit 1; fi
echo "docs browser: ok"
