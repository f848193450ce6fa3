#pragma once
// Self-contained HTML pages for the reports: escaping, base64 data URLs for embedded
// images, and the page frame (system fonts, a max width, figure styles). Nothing on a page
// refers to anything outside it (no scripts, fonts, styles or images by URL), so a report
// reads the same offline.
//
// Every page carries a small inline script (pageCheckScript) that records what a browser
// made of the page on the <html> element, so that a headless browser's dumped DOM shows it:
//   data-errors="N"            script errors seen (window "error" events, capture phase,
//                              so images that fail to load count too); messages in
//                              data-error-messages
//   data-images / data-images-ok   <img> elements, and those decoded (naturalWidth > 0)
//                              once the page has loaded; each decoded <img> gets data-ok="1"
//                              (data-ok="0" when it failed)
//   data-plots                 <svg class="plot"> elements
//   data-checked="1"           the window "load" handler ran
#include <string>
#include <string_view>
#include <vector>

namespace splat::report {

/// Escapes & < > " ' for HTML text and attribute values.
std::string escapeHtml(std::string_view text);
/// Standard base64 (RFC 4648, with padding).
std::string base64(const unsigned char* bytes, std::size_t size);
inline std::string base64(const std::vector<unsigned char>& bytes) {
    return base64(bytes.data(), bytes.size());
}
/// data:`mime`;base64,...
std::string dataUrl(std::string_view mime, const std::vector<unsigned char>& bytes);
/// An <img> embedding `bytes` (PNG or GIF by `mime`), with a class, alt text, a tooltip and
/// a display width in CSS pixels (0: the image's own).
std::string imgTag(const std::vector<unsigned char>& bytes, std::string_view mime,
                   std::string_view cssClass, std::string_view alt, std::string_view title = {},
                   int width = 0);

/// The inline script described above.
std::string pageCheckScript();

/// A page: head (title, style, check script) and the body given.
std::string htmlPage(std::string_view title, std::string_view body);

}  // namespace splat::report
