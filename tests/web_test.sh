#!/usr/bin/env bash
# The browser build in headless Chromium, each page load one TAP stream part, with software GL
# (SwiftShader through ANGLE):
#   ?test&webgl1, ?test&webgl2   the page's self-check (examples/web/demo_web.c): context version, the
#                                tier and GLSL dialect fogvol chose, the composite against a ray caster
#                                and closed-form chords, the scene outside the volumes byte-equal to a
#                                fog-free render; its canvas and a map of the checked pixels:
#                                build/web/webgl1.png, webgl1_checked.png (webgl2 likewise)
#   ?drive&webgl1, ?drive&webgl2 the interactive courtyard (examples/web/courtyard.h) driven by the
#                                page's script with synthetic input (controls changed through the DOM,
#                                key events W and S, mouse and touch pointer drags), checking that the
#                                picture changes as each control says (fog on/off, the gradient ramp and
#                                dithering change nothing outside the volumes' footprint: their meshes
#                                rasterised flat, dilated by a pixel); its pictures:
#                                build/web/webgl1_demo_<step>.png (webgl2 likewise)
#   ?webgl1, ?webgl2             the interactive page, a screenshot: build/web/webgl1_page.png (webgl2)
# usage: tests/web_test.sh [page]     (CHROMIUM=... picks the browser binary)
set -u
page=${1:-${BUILD:-build}/web/demo_web.html}
dir=$(cd "$(dirname "$page")" && pwd)
url="file://$dir/$(basename "$page")"
chrome=${CHROMIUM:-chromium}
profile=$(mktemp -d)
trap 'rm -rf "$profile"' EXIT
n=0; failed=0
for run in test:webgl1 test:webgl2 drive:webgl1 drive:webgl2; do
  mode=${run%%:*} v=${run#*:}
  name=$v; [ "$mode" = drive ] && name=${v}_demo
  dom="$dir/dom_$name.html"
  # the page renders and checks synchronously while it loads (wasm compiled synchronously,
  # embedded in the page; ?drive runs its frames from the page's script the same way), so
  # --dump-dom sees the finished log
  timeout 240 "$chrome" --headless=new --no-sandbox --disable-gpu-sandbox --use-angle=swiftshader \
    --enable-unsafe-swiftshader --user-data-dir="$profile" --window-size=800,700 --dump-dom "$url?$mode&$v" \
    > "$dom" 2> "$dir/chromium_$name.log"
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
      "png demo_"*)
        shot=${line#png }; shot=${shot%% *}
        echo "${line#png $shot }" | base64 -d > "$dir/${v}_$shot.png" && echo "# picture: $dir/${v}_$shot.png" ;;
      "#"*) echo "$line" ;;
    esac
  done <<< "$log"
  title=$(grep -o '<title>[^<]*' "$dom" | head -1 | sed 's/<title>//')
  n=$((n + 1))
  if [ "$rc" = 0 ] && [ "$title" = "fogvol-web: PASS" ]; then
    echo "ok $n - $v ($mode): page finished and passed"
  else
    echo "not ok $n - $v ($mode): page title \"$title\", chromium exit status $rc (see $dir/chromium_$name.log)"
    failed=1
  fi
done
# the interactive page as a visitor sees it (controls and the frame time under the canvas), one
# screenshot per WebGL version: build/web/webgl1_page.png, webgl2_page.png
for v in webgl1 webgl2; do
  shot="$dir/${v}_page.png"
  rm -f "$shot"
  timeout 120 "$chrome" --headless=new --no-sandbox --disable-gpu-sandbox --use-angle=swiftshader \
    --enable-unsafe-swiftshader --user-data-dir="$profile" --window-size=800,520 --virtual-time-budget=250 \
    --screenshot="$shot" "$url?$v" > /dev/null 2> "$dir/chromium_${v}_page.log"
  n=$((n + 1))
  if [ -s "$shot" ] && [ "$(stat -c %s "$shot")" -gt 20000 ]; then
    echo "ok $n - $v: the interactive page's screenshot $shot"
  else
    echo "not ok $n - $v: no screenshot of the interactive page (see $dir/chromium_${v}_page.log)"
    failed=1
  fi
done
echo "1..$n"
[ "$failed" = 0 ]
