//! The HTML page of `arc view`: the vendored three.js module, the page's script and
//! the scene's JSON, all inlined, so the one file works offline from disk.

use super::scene::Scene;

/// three.js 0.170.0, `build/three.module.min.js` (MIT; host-sim/assets/README.md).
const THREE_JS: &str = include_str!("../../../../assets/three-0.170.0/three.module.min.js");
/// The page's own script: builds the 3D scene from the JSON block.
const VIEW_JS: &str = include_str!("view.js");
/// The page's style.
const VIEW_CSS: &str = include_str!("view.css");
/// Runs first: any error, even in the module scripts, becomes a marker in the page
/// (what a headless check reads with `--dump-dom`).
const ERROR_JS: &str = "window.arcFail = function (m) { var d = document.getElementById('arc-view-error') || document.createElement('pre'); d.id = 'arc-view-error'; d.textContent = 'ARC-VIEW-ERROR: ' + m; document.body.appendChild(d); };\n\
window.addEventListener('error', function (e) { arcFail(e.message || String(e)); });\n\
window.addEventListener('unhandledrejection', function (e) { arcFail(String(e.reason)); });";

/// Text safe inside an HTML element.
fn escape_html(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// The page showing `scene`.
pub fn html(scene: &Scene) -> String {
    // `<` only occurs inside JSON strings, where `\u003c` means the same: the block
    // can then never close its script element early.
    let json = serde_json::to_string(scene)
        .expect("a scene always serialises")
        .replace('<', "\\u003c");
    let title = escape_html(&scene.title);
    format!(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
         <title>arc view: {title}</title>\n<style>\n{VIEW_CSS}</style>\n\
         <script>\n{ERROR_JS}\n</script>\n</head>\n<body>\n\
         <div id=\"panel\"><div id=\"title\">{title}</div>\n\
         <div class=\"row\"><button id=\"play\" title=\"play / pause (space)\">play</button>\
         <input id=\"time\" type=\"range\" min=\"0\" max=\"1\" step=\"0.01\" value=\"0\">\
         <select id=\"speed\" title=\"playback speed\"><option>1</option><option selected>4</option><option>16</option><option>64</option></select>x</div>\n\
         <div id=\"info\"></div>\n\
         <div class=\"row\"><label>cut obstacles above z <input id=\"cut\" type=\"range\" min=\"0\" max=\"1\" step=\"0.05\" value=\"1\"></label> <span id=\"cutv\"></span> <label title=\"keep the camera on the chain\"><input id=\"follow\" type=\"checkbox\">follow</label></div>\n\
         <div class=\"hint\">drag: orbit, right-drag or shift-drag: pan, wheel: zoom; the address's #t=SECONDS sets the time</div></div>\n\
         <div id=\"legend\"></div>\n\
         <script type=\"application/json\" id=\"arc-data\">{json}</script>\n\
         <script type=\"text/plain\" id=\"three-src\">{THREE_JS}</script>\n\
         <script type=\"module\">\n{VIEW_JS}</script>\n</body>\n</html>\n"
    )
}
