#!/usr/bin/env bash
# The browser build in headless Chromium: loads build/web/demo_web.html once as WebGL1
# (?webgl1) and once as WebGL2 (?webgl2) with software GL (SwiftShader through ANGLE), and
# reports what the page checked about itself (examples/web/demo_web.c: context version, the
# tier and GLSL dialect fogvol chose, the composite against a ray caster and closed-form
# chords, the scene outside the volumes byte-equal to a fog-free render) as one TAP stream.
# The page also prints the canvas as a PNG: written to build/web/webgl1.png, webgl2.png, and a map of
# the checked pixels and their errors: build/web/webgl1_checked.png, webgl2_checked.png.
# usage: tests/web_test.sh [page]     (CHROMIUM=... picks the browser binary)
set -u
page=${1:-${BUILD:-build}/web/demo_web.html}
dir=$(cd "$(dirname "$page")" && pwd)
url="file://$dir/$(basename "$page")"
chrome=${CHROMIUM:-chromium}
profile=$(mktemp -d)
trap 'rm -rf "$profile"' EXIT
n=0; failed=0
for v in webgl1 webgl2; do
  dom="$dir/dom_$v.html"
  # the page renders and checks synchronously while it loads (wasm compiled synchronously,
  # embedded in the page), so --dump-dom sees the finished log
  timeout 120 "$chrome" --headless=new --no-sandbox --disable-gpu-sandbox --use-angle=swiftshader \
    --enable-unsafe-swiftshader --user-data-dir="$profile" --dump-dom "$url?$v" \
    > "$dom" 2> "$dir/chromium_$v.log"
  rc=$?
  log=$(sed -n '/<pre id="log">/,/<\/pre>/p' "$dom" | sed -e 's/<pre id="log">//' -e 's/<\/pre>.*//' \
        -e 's/&lt;/</g' -e 's/&gt;/>/g' -e 's/&quot;/"/g' -e 's/&amp;/\&/g')
  while IFS= read -r line; do
    case "$line" in
      "ok "*|"not ok "*)
        n=$((n + 1))
        case "$line" in "not ok"*) failed=1 ;; esac
        echo "$line" | sed -E "s/^(ok|not ok) [0-9]+/\1 $n/" ;;
      "png canvas "*) echo "${line#png canvas }" | base64 -d > "$dir/$v.png" && echo "# canvas: $dir/$v.png" ;;
      "png error "*) echo "${line#png error }" | base64 -d > "$dir/${v}_checked.png" && echo "# where the checks looked: $dir/${v}_checked.png" ;;
      "#"*) echo "$line" ;;
    esac
  done <<< "$log"
  title=$(grep -o '<title>[^<]*' "$dom" | head -1 | sed 's/<title>//')
  n=$((n + 1))
  if [ "$rc" = 0 ] && [ "$title" = "fogvol-web: PASS" ]; then
    echo "ok $n - $v: page finished and passed"
  else
    echo "not ok $n - $v: page title \"$title\", chromium exit status $rc (see $dir/chromium_$v.log)"
    failed=1
  fi
done
echo "1..$n"
[ "$failed" = 0 ]
