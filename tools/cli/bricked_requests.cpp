// Bricked frames on request (bricked_requests.h).
#include "bricked_requests.h"

#include <cstdint>
#include <cstring>
#include <type_traits>
#include <vector>

#include "splat/error.h"

namespace splat::cli {

namespace {

// A request: [u8 what][i32 renderer][CameraParams]; `what` is a frame, or the end.
enum What : std::uint8_t { kFrame = 1, kEndOk = 2, kEndFailed = 3 };
static_assert(std::is_trivially_copyable_v<CameraParams>);
constexpr std::size_t kRequestBytes = 1 + sizeof(std::int32_t) + sizeof(CameraParams);

std::vector<unsigned char> encode(What what, RendererKind renderer, const CameraParams& camera) {
    std::vector<unsigned char> m(kRequestBytes);
    const std::int32_t r = std::int32_t(renderer);
    m[0] = what;
    std::memcpy(&m[1], &r, sizeof r);
    std::memcpy(&m[1 + sizeof r], &camera, sizeof camera);
    return m;
}

}  // namespace

BrickedFrameRequests::BrickedFrameRequests(BrickedFrames& frames, BrickGroup& group)
    : frames_(frames), group_(group) {}

BrickedFrameRequests::~BrickedFrameRequests() {
    if (group_.rank() == 0) end(false);
}

Image BrickedFrameRequests::render(const CameraParams& camera, RendererKind renderer,
                                   RenderStats* stats) {
    if (ended_) throw Error("bricked frames: a frame requested after the end");
    std::vector<unsigned char> m = encode(kFrame, renderer, camera);
    group_.broadcast(m);
    ++count_;
    return frames_.render(camera, renderer, stats);
}

void BrickedFrameRequests::end(bool ok) {
    if (ended_ || group_.rank() != 0) return;
    ended_ = true;
    std::vector<unsigned char> m = encode(ok ? kEndOk : kEndFailed, RendererKind::Axis, {});
    group_.broadcast(m);
}

bool BrickedFrameRequests::serve() {
    for (;;) {
        std::vector<unsigned char> m;
        group_.broadcast(m);
        if (m.size() != kRequestBytes) throw Error("bricked frames: a malformed request");
        if (m[0] != kFrame) return m[0] == kEndOk;
        std::int32_t r = 0;
        CameraParams camera;
        std::memcpy(&r, &m[1], sizeof r);
        std::memcpy(static_cast<void*>(&camera), &m[1 + sizeof r], sizeof camera);
        ++count_;
        try {
            frames_.render(camera, RendererKind(r));
        } catch (const std::exception&) {
            // Every rank failed this frame alike (BrickedFrames agrees before compositing):
            // rank 0 reports it and ends the requests.
        }
    }
}

}  // namespace splat::cli
