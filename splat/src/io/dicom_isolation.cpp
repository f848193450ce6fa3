// GDCM kept from harming the process. Debian's GDCM allocates an element's value from its
// length field before reading it and keeps its assertions, so a malformed file could make it
// allocate gigabytes or abort the process: every file is first walked here element by
// element (checkDicomLengths), and every GDCM parse runs in a forked child
// (survivesInChild) whose death becomes one error line.
#include <gdcmDicts.h>
#include <gdcmGlobal.h>
#include <gdcmTrace.h>

#include <csignal>
#include <cstdio>
#include <cstring>

#include "dicom_detail.h"
#include "io/parse_in_child.h"

namespace splat::detail {
namespace {

/// A tag as DICOM writes it: (7fe0,0010).
std::string hexTag(std::uint32_t group, std::uint32_t element) {
    char buf[16];
    std::snprintf(buf, sizeof buf, "(%04x,%04x)", unsigned(group & 0xFFFF),
                  unsigned(element & 0xFFFF));
    return buf;
}

}  // namespace

void quietGdcm() {
    gdcm::Trace::DebugOff();
    gdcm::Trace::WarningOff();
    gdcm::Trace::ErrorOff();
}

// GDCM allocates an element's value from its length field before reading it, so a
// 100-byte file declaring a 4 GB element would allocate 4 GB. This walk over the element
// headers (Part 10 files: preamble, explicit-VR meta group, then the data set in its
// transfer syntax) checks every defined length against the bytes that follow before GDCM
// sees the file. Sequences and items of undefined length are walked into; in implicit VR
// the public dictionary says which tags are sequences, as it does for GDCM.
DicomLayout checkDicomLengths(const std::vector<unsigned char>& b, const std::string& name) {
    DicomLayout layout;
    auto fail = [&](const std::string& why) {
        throw Error(name + ": malformed DICOM file (" + why + ")");
    };
    if (b.size() < 132 || std::memcmp(&b[128], "DICM", 4) != 0)
        fail("no DICM marker after the 128-byte preamble: only DICOM Part 10 files are read");
    static const std::string longVrs = "OBODOFOLOVOWSQSVUCUNURUTUV";
    static const std::string shortVrs = "AEASATCSDADSDTFLFDISLOLTPNSHSLSSSTTMUIULUS";
    const gdcm::Dicts& dicts = gdcm::Global::GetInstance().GetDicts();
    std::size_t pos = 132;
    bool inMeta = true, explicitVr = true, bigEndian = false;
    std::string syntax;
    auto read16 = [&](std::size_t at, bool be) {
        return be ? std::uint32_t(b[at] << 8 | b[at + 1]) : std::uint32_t(b[at] | b[at + 1] << 8);
    };
    auto read32 = [&](std::size_t at, bool be) {
        return be ? (read16(at, true) << 16 | read16(at + 2, true))
                  : (read16(at, false) | read16(at + 2, false) << 16);
    };
    auto isVr = [](const std::string& list, const char* vr) {
        for (std::size_t i = 0; i + 1 < list.size(); i += 2)
            if (list[i] == vr[0] && list[i + 1] == vr[1]) return true;
        return false;
    };
    // One entry per open sequence of undefined length: true when its content is implicit
    // VR little endian (an undefined-length UN, PS3.5 6.2.2, and everything inside it).
    std::vector<bool> scopes;
    // The ends of the open items and sequences of defined length: GDCM reads such a value
    // as a bounded block and resumes at its declared end, so an element that crosses that
    // end would make GDCM and this walk part ways (found by fuzz_dicom): refused.
    std::vector<std::size_t> ends;
    auto within = [&](std::uint64_t upTo) {
        if (!ends.empty() && upTo > ends.back())
            fail("an element crosses the end of its item or sequence");
    };
    while (pos < b.size()) {
        while (!ends.empty() && pos == ends.back()) ends.pop_back();
        within(pos);
        if (b.size() - pos < 8) fail("truncated element header");
        if (inMeta && read16(pos, false) != 0x0002) {
            inMeta = false;
            while (!syntax.empty() && (syntax.back() == '\0' || syntax.back() == ' '))
                syntax.pop_back();
            if (syntax == "1.2.840.10008.1.2.1.99")
                fail("deflated transfer syntax is not supported");
            // GDCM guesses the encoding when the meta group or its transfer syntax is missing
            // or unknown, and its guess can part ways with this walk (found by fuzz_dicom):
            // such files are refused, not guessed at.
            if (pos == 132) fail("no file meta information (group 0002) after DICM");
            if (syntax.empty()) fail("no transfer syntax (0002,0010) in the file meta information");
            if (syntax != "1.2.840.10008.1.2" && syntax != "1.2.840.10008.1.2.1" &&
                syntax != "1.2.840.10008.1.2.2" && syntax != "1.2.840.10008.1.2.5" &&
                !syntax.starts_with("1.2.840.10008.1.2.4."))
                fail("unknown transfer syntax '" + syntax.substr(0, 64) + "'");
            explicitVr = syntax != "1.2.840.10008.1.2";
            bigEndian = syntax == "1.2.840.10008.1.2.2";
            // A data set written in implicit VR under an explicit-VR transfer syntax (pydicom's
            // SC_rgb_jpeg.dcm): no VR where the first element's VR belongs. pydicom guesses
            // and reads it; GDCM's recovery runs out of memory on it. Refused, naming that.
            if (explicitVr && b.size() - pos >= 8) {
                const char vr[2] = {char(b[pos + 4]), char(b[pos + 5])};
                if (!isVr(longVrs, vr) && !isVr(shortVrs, vr))
                    fail("the data set is encoded in implicit VR, but its transfer syntax " +
                         syntax + " says explicit VR");
            }
        }
        const bool forced = !scopes.empty() && scopes.back();
        const bool ex = inMeta || (explicitVr && !forced), be = !inMeta && bigEndian && !forced;
        const std::uint32_t group = read16(pos, be), element = read16(pos + 2, be);
        if (group == 0xFFFE) {  // item or delimiter: tag + 4-byte length, no VR
            const std::uint32_t len = read32(pos + 4, be);
            pos += 8;
            // PS3.5 7.5: group fffe holds only the item (e000) and the item (e00d) and
            // sequence (e0dd) delimiters; GDCM reads anything else as an element.
            if (element != 0xE000 && element != 0xE00D && element != 0xE0DD)
                fail("invalid item tag " + hexTag(group, element));
            if (element == 0xE000 && len != 0xFFFFFFFFu && len > b.size() - pos)
                fail("an item declares " + std::to_string(len) + " bytes, the file holds " +
                     std::to_string(b.size() - pos));
            if (element == 0xE000 && len != 0xFFFFFFFFu) {
                within(pos + len);
                if (len > 0) ends.push_back(pos + len);
            }
            if (element == 0xE0DD && !scopes.empty()) scopes.pop_back();
            continue;  // walk into items; delimiters have no value
        }
        std::uint64_t len = 0;
        bool sequence = false, unknown = false;
        if (ex) {
            const char vr[2] = {char(b[pos + 4]), char(b[pos + 5])};
            if (isVr(longVrs, vr)) {
                if (b.size() - pos < 12) fail("truncated element header");
                len = read32(pos + 8, be);
                pos += 12;
            } else if (isVr(shortVrs, vr)) {
                len = read16(pos + 6, be);
                pos += 8;
            } else {
                fail("unknown value representation in element " + hexTag(group, element));
            }
            sequence = vr[0] == 'S' && vr[1] == 'Q';
            unknown = vr[0] == 'U' && vr[1] == 'N';
        } else {
            len = read32(pos + 4, be);
            pos += 8;
            const gdcm::VR vr =
                dicts.GetDictEntry(gdcm::Tag(std::uint16_t(group), std::uint16_t(element))).GetVR();
            sequence = vr == gdcm::VR::SQ;
        }
        // GDCM asserts (aborts the process) on a sequence or an undefined length in the meta
        // group, and on a file that ends inside it.
        if (inMeta && (sequence || len == 0xFFFFFFFFu))
            fail("a sequence or undefined length in the file meta information");
        // Pixel Data: a nested one (icon) comes before the top-level one, which is last.
        const bool pixels = group == 0x7FE0 && element == 0x0010;
        if (pixels) {
            layout.pixelData = true;
            layout.encapsulated = len == 0xFFFFFFFFu;
            layout.pixelOffset = pos;
            layout.pixelLength = len == 0xFFFFFFFFu ? 0 : len;
        }
        if (pixels && len == 0xFFFFFFFFu) {
            // Encapsulated (compressed) pixels, PS3.5 A.4: an offset table item, then one
            // item per fragment, then a sequence delimiter. Fragments hold codestreams,
            // not elements.
            while (true) {
                if (b.size() - pos < 8) fail("encapsulated Pixel Data ends without its delimiter");
                const std::uint32_t g = read16(pos, be), el = read16(pos + 2, be);
                const std::uint32_t flen = read32(pos + 4, be);
                pos += 8;
                if (g == 0xFFFE && el == 0xE0DD) break;
                if (g != 0xFFFE || el != 0xE000 || flen == 0xFFFFFFFFu)
                    fail("encapsulated Pixel Data holds " + hexTag(g, el) +
                         " where a fragment item belongs");
                if (flen > b.size() - pos)
                    fail("a Pixel Data fragment declares " + std::to_string(flen) +
                         " bytes, the file holds " + std::to_string(b.size() - pos));
                if (layout.pixelLength == 0 && flen > 0 && layout.pixelOffset + 8 < pos) {
                    layout.pixelOffset = pos;  // the first fragment after the offset table
                    layout.pixelLength = flen;
                }
                pos += flen;
            }
            continue;
        }
        if (len == 0xFFFFFFFFu) {  // undefined length: walk into its items
            scopes.push_back(forced || unknown);
            continue;
        }
        if (len > b.size() - pos)
            fail("element " + hexTag(group, element) + " declares " + std::to_string(len) +
                 " bytes, the file holds " + std::to_string(b.size() - pos));
        within(pos + len);
        if (sequence && len > 0) ends.push_back(pos + std::size_t(len));
        if (inMeta && group == 0x0002 && element == 0x0010)
            syntax.assign(reinterpret_cast<const char*>(&b[pos]), std::size_t(len));
        if (!sequence) pos += std::size_t(len);  // a sequence's items are checked too
    }
    if (inMeta) fail("no data set after the file meta information");
    layout.bigEndian = bigEndian;
    layout.syntax = syntax;
    return layout;
}

/// Runs `work` in a forked child (parse_in_child.h) and reports how the child ended. Debian's
/// GDCM keeps its assertions: a malformed file can abort the process inside gdcm::Reader
/// (SIGABRT from gdcm::DataSet::ReadNested, FileMetaInformation::ReadCompat, ...). Each GDCM
/// parse is first tried in a child; a child killed by a signal becomes one error line. GDCM's
/// recovery heuristics (explicit/implicit mixes, guessed byte orders) can read a length the
/// element walk never saw and allocate it: the child's address space is capped at its present
/// size + 1 GiB, and an allocation that fails is reported. A child that exits otherwise (a
/// sanitizer) leaves the verdict to the parent's own parse. Measured cost: docs/decisions.md
/// (fork per slice of a 500-slice series).
void survivesInChild(const std::string& name, const char* what, const std::function<void()>& work) {
    const ChildEnd end = runInChild(name, "DICOM", ChildMemory::PresentPlusGiB, work);
    if (end.kind == ChildEnd::OutOfMemory)
        throw Error(name + ": malformed DICOM file (GDCM " + what +
                    " ran out of memory: a length the file cannot hold)");
    if (end.kind == ChildEnd::Signalled)
        throw Error(name + ": malformed DICOM file (GDCM " + what + " died on it with " +
                    (end.code == SIGABRT   ? std::string("SIGABRT, a failed assertion")
                     : end.code == SIGALRM ? std::string("a timeout")
                                           : "signal " + std::to_string(end.code)) +
                    ")");
}

}  // namespace splat::detail
