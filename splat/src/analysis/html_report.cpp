// Self-contained HTML pages (see html_report.h).
#include "analysis/html_report.h"

namespace splat::report {

std::string escapeHtml(std::string_view text) {
    std::string out;
    out.reserve(text.size());
    for (char c : text) {
        switch (c) {
            case '&':
                out += "&amp;";
                break;
            case '<':
                out += "&lt;";
                break;
            case '>':
                out += "&gt;";
                break;
            case '"':
                out += "&quot;";
                break;
            case '\'':
                out += "&#39;";
                break;
            default:
                out += c;
        }
    }
    return out;
}

std::string base64(const unsigned char* bytes, std::size_t size) {
    static const char* digits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    out.reserve((size + 2) / 3 * 4);
    std::size_t i = 0;
    for (; i + 2 < size; i += 3) {
        const unsigned v = unsigned(bytes[i]) << 16 | unsigned(bytes[i + 1]) << 8 | bytes[i + 2];
        out += digits[v >> 18 & 63];
        out += digits[v >> 12 & 63];
        out += digits[v >> 6 & 63];
        out += digits[v & 63];
    }
    if (i + 1 == size) {
        const unsigned v = unsigned(bytes[i]) << 16;
        out += digits[v >> 18 & 63];
        out += digits[v >> 12 & 63];
        out += "==";
    } else if (i + 2 == size) {
        const unsigned v = unsigned(bytes[i]) << 16 | unsigned(bytes[i + 1]) << 8;
        out += digits[v >> 18 & 63];
        out += digits[v >> 12 & 63];
        out += digits[v >> 6 & 63];
        out += '=';
    }
    return out;
}

std::string dataUrl(std::string_view mime, const std::vector<unsigned char>& bytes) {
    std::string out = "data:";
    out += mime;
    out += ";base64,";
    out += base64(bytes);
    return out;
}

std::string imgTag(const std::vector<unsigned char>& bytes, std::string_view mime,
                   std::string_view cssClass, std::string_view alt, std::string_view title,
                   int width) {
    std::string out = "<img class=\"";
    out += escapeHtml(cssClass);
    out += "\" alt=\"";
    out += escapeHtml(alt);
    out += '"';
    if (!title.empty()) {
        out += " title=\"";
        out += escapeHtml(title);
        out += '"';
    }
    if (width > 0) out += " width=\"" + std::to_string(width) + '"';
    out += " src=\"";
    out += dataUrl(mime, bytes);
    out += "\">";
    return out;
}

std::string pageCheckScript() {
    return R"JS(<script>
(function () {
  var root = document.documentElement, errors = [];
  root.setAttribute("data-errors", "0");
  window.addEventListener("error", function (e) {
    var what = e.message || (e.target && e.target.tagName ? "cannot load " + e.target.tagName : "error");
    errors.push(String(what));
    root.setAttribute("data-errors", String(errors.length));
    root.setAttribute("data-error-messages", errors.join(" | "));
  }, true);
  window.addEventListener("load", function () {
    var imgs = document.images, ok = 0;
    for (var i = 0; i < imgs.length; ++i) {
      var good = imgs[i].complete && imgs[i].naturalWidth > 0;
      imgs[i].setAttribute("data-ok", good ? "1" : "0");
      if (good) ++ok;
    }
    root.setAttribute("data-images", String(imgs.length));
    root.setAttribute("data-images-ok", String(ok));
    root.setAttribute("data-plots", String(document.querySelectorAll("svg.plot").length));
    root.setAttribute("data-checked", "1");
  });
})();
</script>
)JS";
}

namespace {

const char* kStyle = R"CSS(<style>
:root { color-scheme: light; }
body { font-family: system-ui, -apple-system, "Segoe UI", Roboto, "Helvetica Neue", Arial,
       "Noto Sans", "Liberation Sans", sans-serif; font-size: 15px; line-height: 1.45;
       color: #1d1d1f; background: #fafafa; margin: 0; }
main { max-width: 1040px; margin: 0 auto; padding: 24px 28px 64px; background: #fff; }
h1 { font-size: 1.6em; margin: 0.2em 0 0.4em; }
h2 { font-size: 1.25em; margin: 1.8em 0 0.5em; border-bottom: 1px solid #ddd; padding-bottom: 4px; }
h3 { font-size: 1.05em; margin: 1.4em 0 0.4em; }
pre, code { font-family: ui-monospace, "SFMono-Regular", "DejaVu Sans Mono", Menlo, Consolas,
            monospace; font-size: 0.9em; }
pre { background: #f3f3f3; padding: 8px 10px; border-radius: 4px; white-space: pre-wrap;
      word-break: break-all; }
table { border-collapse: collapse; margin: 0.5em 0 1em; }
th, td { border: 1px solid #ddd; padding: 3px 9px; text-align: right; }
th { background: #f3f3f3; }
td.l, th.l { text-align: left; }
table.kv td:first-child { text-align: left; font-family: ui-monospace, monospace; }
table.kv td:last-child { text-align: left; }
figure { margin: 1em 0 1.4em; }
figcaption { font-size: 0.9em; color: #444; margin-top: 4px; }
svg.plot { display: block; max-width: 100%; height: auto; font-family: inherit; }
svg.plot .plot-title { font-size: 13px; font-weight: 600; }
.grid { display: grid; gap: 8px 12px; align-items: start; }
.grid .cell { font-size: 0.85em; text-align: center; color: #333; }
.grid img { display: block; width: 100%; height: auto; image-rendering: pixelated;
            background: #000; }
img.animation { image-rendering: pixelated; max-width: 100%; }
.note { color: #666; font-size: 0.9em; }
.event-yes { color: #b3261e; font-weight: 600; }
</style>
)CSS";

}  // namespace

std::string htmlPage(std::string_view title, std::string_view body) {
    std::string out = "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n";
    out += "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n<title>";
    out += escapeHtml(title);
    out += "</title>\n";
    out += kStyle;
    out += pageCheckScript();
    out += "</head>\n<body>\n<main>\n";
    out += body;
    out += "</main>\n</body>\n</html>\n";
    return out;
}

}  // namespace splat::report
