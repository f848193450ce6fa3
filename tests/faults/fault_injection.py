#!/usr/bin/python3
"""Fault injection for splat's writers and --resume (docs/reliability.md).

Usage: fault_injection.py SPLAT_EXE WORK_DIR [SEED]

Cases, each asserting the exit status, one clear error line naming the file and the OS
error, no empty or partial file, previous outputs intact, and a rerun (rotate: --resume)
that completes to byte-identical outputs:
  full disk      a 600 KiB tmpfs filled up (needs mount: root), and always an RLIMIT_FSIZE
                 limit (SIGXFSZ ignored: write(2) fails with EFBIG "File too large"),
                 which also makes a write fail in the middle of a file;
  unwritable     a read-only tmpfs (root) or a chmod 0555 folder (not root);
  disappearing   frames deleted, truncated or emptied between a run and --resume;
  external       an ffmpeg that fails after writing part of its file, one that writes nothing;
  killed         SIGKILL / SIGINT at random moments of render, rotate, popping and study,
                 then the same command (rotate, popping, study: with --resume).
Prints one line per case; exits 1 when any assertion failed.
"""
import atexit
import hashlib
import json
import os
import random
import re
import resource
import shutil
import signal
import subprocess
import sys
import time

SPLAT, WORK = sys.argv[1], sys.argv[2]
SEED = int(sys.argv[3]) if len(sys.argv) > 3 else random.randrange(1 << 30)
rng = random.Random(SEED)
VOL = "synthetic:phantom:48"
TEMP = re.compile(r"^\..+\.tmp[0-9]+-[0-9]+(\..*)?$")
failures = []
mounts = []


@atexit.register
def unmount():
    for m in reversed(mounts):
        subprocess.run(["umount", m], capture_output=True)
    mounts.clear()


def check(cond, what):
    if not cond:
        failures.append(what)
        print("  FAIL:", what)
    return cond


def run(args, fsize=None, env=None, timeout=120):
    def limit():
        if fsize is not None:
            signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
            resource.setrlimit(resource.RLIMIT_FSIZE, (fsize, fsize))

    p = subprocess.run([SPLAT] + args, capture_output=True, text=True, preexec_fn=limit,
                       timeout=timeout, env=env)
    return p.returncode, p.stdout, p.stderr


def md5(path):
    with open(path, "rb") as f:
        return hashlib.md5(f.read()).hexdigest()


def state(d):
    """name -> md5 of every file under d (hidden ones too)."""
    out = {}
    for root, _, files in os.walk(d):
        for f in files:
            p = os.path.join(root, f)
            out[os.path.relpath(p, d)] = md5(p)
    return out


def check_clean(d, case, temporaries_ok=False):
    """No empty file, and (unless a killed run left them) no temporary. A SIGKILL can land
    between a temporary's creation and its first write, so a killed run's hidden temporary
    may be empty; every file a user sees must not."""
    for root, _, files in os.walk(d):
        for f in files:
            p = os.path.join(root, f)
            if TEMP.match(f):
                check(temporaries_ok, f"{case}: temporary left behind: {p}")
                continue
            check(os.path.getsize(p) > 0, f"{case}: empty file {p}")


def check_error(rc, err, case, name, oserrors):
    lines = [l for l in err.splitlines() if l.strip()]
    check(rc == 1, f"{case}: exit status {rc}, expected 1 ({err.strip()})")
    if check(len(lines) == 1, f"{case}: expected one error line, got {lines}"):
        line = lines[0]
        check(line.startswith("splat: error: ") and name in line,
              f"{case}: error line does not name {name}: {line}")
        check(any(o in line for o in oserrors), f"{case}: no OS error {oserrors} in: {line}")


def mount_tmpfs(path, opts):
    os.makedirs(path, exist_ok=True)
    p = subprocess.run(["mount", "-t", "tmpfs", "-o", opts, "tmpfs", path],
                       capture_output=True, text=True)
    if p.returncode == 0:
        mounts.append(path)
        return True
    return False


def fill(d, leave):
    """Fills the file system of d, then frees `leave` bytes (a write then fails mid-file)."""
    filler = os.path.join(d, "filler")
    fd = os.open(filler, os.O_WRONLY | os.O_CREAT | os.O_TRUNC)
    try:
        while True:
            os.write(fd, b"\0" * 4096)
    except OSError:
        pass
    os.close(fd)
    os.truncate(filler, max(0, os.path.getsize(filler) - leave))
    return filler


# ---- clean references ----------------------------------------------------------------

ROT = ["rotate", VOL, "--size", "128x128", "--frames", "36", "-q"]
POP = ["popping", VOL, "--size", "48x48", "--from", "40", "--to", "50", "--step", "1",
       "--refine", "3", "-q"]
STUDY = ["study", VOL, "--size", "48x48", "--sweep", "renderer=axis,sheet",
         "--sweep", "slab=1,0.5", "--repeats", "1", "--warmup", "0", "-q"]
REF = os.path.join(WORK, "ref")
shutil.rmtree(WORK, ignore_errors=True)
os.makedirs(REF)
print(f"fault injection, seed {SEED} (rerun: fault_injection.py SPLAT DIR {SEED})")
for ext in ("png", "exr", "tif"):
    rc, _, err = run(["render", VOL, "--size", "200x200", "-o", f"{REF}/big.{ext}"])
    check(rc == 0, f"reference render {ext}: {err}")
    rc, _, err = run(["render", VOL, "--size", "32x32", "-o", f"{REF}/small.{ext}"])
    check(rc == 0, f"reference small render {ext}: {err}")
rc, _, err = run(ROT + ["-o", f"{REF}/turn"])
check(rc == 0, f"reference rotate: {err}")


def clean_run(args, out):
    """The state of `out` after an uninterrupted run (files embed their own path, so the
    reference is made at the same path, then removed)."""
    shutil.rmtree(out, ignore_errors=True)
    os.makedirs(out)
    rc, _, err = run(args)
    check(rc == 0, f"clean run {args[0]}: {err}")
    st = state(out) if os.path.isdir(out) else {}
    shutil.rmtree(out, ignore_errors=True)
    return st
rc, _, err = run(POP + ["--report", f"{REF}/pop"])
check(rc == 0, f"reference popping: {err}")
rc, _, err = run(STUDY + ["--report", f"{REF}/study"])
check(rc == 0, f"reference study: {err}")


def study_accuracy(d):
    """The study's measured accuracy (timings differ from run to run; these do not)."""
    with open(os.path.join(d, "study.json")) as f:
        j = json.load(f)
    keys = ("label", "splats", "footprint_pixels", "rmse", "psnr", "max_abs", "flip")
    return [{k: p.get(k) for k in keys} for p in j["points"]]


def frames_only(s):
    return {k: v for k, v in s.items() if k.startswith("frame_")}


# ---- full disk and a write failing in the middle of a file -----------------------------

def full_disk_cases(d, how, limit, oserr, squeeze):
    """Every writer on a full disk (`limit`: RLIMIT_FSIZE, or None on a full tmpfs;
    squeeze(n) leaves n bytes free)."""
    case = f"full disk ({how})"
    # Single images over a previous good one (a write that fails mid-file).
    for ext in ("png", "exr", "tif"):
        target = os.path.join(d, f"a.{ext}")
        squeeze(None)
        shutil.copy(f"{REF}/small.{ext}", target)
        before = md5(target)
        squeeze(4096)
        rc, _, err = run(["render", VOL, "--size", "200x200", "-o", target], fsize=limit)
        check_error(rc, err, f"{case} render .{ext}", target, oserr)
        check(md5(target) == before, f"{case} render .{ext}: previous file changed")
    # Reports over previous ones: all of a report or none of it.
    for name, args, files in (
            ("popping", POP, ["report.html", "metrics.csv", "summary.json"]),
            ("study", STUDY, ["study.csv", "study.json", "pareto.svg", "pareto.png"])):
        rep = os.path.join(d, name)
        squeeze(None)
        shutil.rmtree(rep, ignore_errors=True)
        os.makedirs(rep)
        for f in files:
            with open(os.path.join(rep, f), "w") as out:
                out.write("previous " + f + "\n")
        before = state(rep)
        squeeze(8192)
        rc, _, err = run(args + ["--report", rep], fsize=limit)
        check_error(rc, err, f"{case} {name}", rep, oserr)
        after = state(rep)
        check(all(after.get(f) == before[f] for f in files),
              f"{case} {name}: a previous report file changed")
    # A rotation: frames until the disk is full, then --resume once there is room.
    turn = os.path.join(d, "turn")
    gif = os.path.join(d, "turn.gif")
    args = ROT + ["-o", turn, "--gif", gif]
    squeeze(None)
    for n in os.listdir(d):  # room for the rotation on the small tmpfs
        p = os.path.join(d, n)
        shutil.rmtree(p) if os.path.isdir(p) else os.remove(p)
    ref = clean_run(args, turn)
    with open(gif, "wb") as f:
        f.write(b"previous gif")
    squeeze(48 * 1024)
    rc, _, err = run(args, fsize=limit)
    check_error(rc, err, f"{case} rotate", turn, oserr)
    check_clean(turn, f"{case} rotate")
    s = frames_only(state(turn))
    check(len(s) < 36, f"{case} rotate: {len(s)} frames written on a full disk")
    check(all(ref[k] == v for k, v in s.items()),
          f"{case} rotate: a written frame differs from the clean run")
    with open(gif, "rb") as f:
        check(f.read() == b"previous gif", f"{case} rotate: previous GIF changed")
    if limit is not None:
        # Frames that fit, then a GIF or a contact sheet that does not (after every frame).
        small = ["rotate", VOL, "--size", "32x32", "--frames", "36", "-q", "--overwrite"]
        for flag, name in (("--gif", "sheet.gif"), ("--contact-sheet", "sheet.png")):
            target = os.path.join(d, name)
            with open(target, "wb") as f:
                f.write(b"previous " + name.encode())
            rc, _, err = run(small + ["-o", os.path.join(d, "small"), flag, target], fsize=limit)
            check_error(rc, err, f"{case} rotate {flag}", target, oserr)
            with open(target, "rb") as f:
                check(f.read() == b"previous " + name.encode(), f"{case} {flag}: previous changed")
            check_clean(os.path.join(d, "small"), f"{case} rotate {flag}")
    squeeze(None)
    rc, _, err = run(args + ["--resume"])
    check(rc == 0, f"{case} rotate --resume: {err}")
    check(state(turn) == ref, f"{case} rotate --resume: frames differ from the clean run")
    check_clean(turn, f"{case} rotate --resume")


# RLIMIT_FSIZE: no mount needed; 4 KiB lets small files through (a manifest, a CSV) and
# stops the others part way (every frame and image here is larger).
print("case: full disk and mid-file write errors through RLIMIT_FSIZE (EFBIG)")
d = os.path.join(WORK, "rlimit")
os.makedirs(d)
full_disk_cases(d, "RLIMIT_FSIZE", 4096, ["File too large"], lambda n: None)

TMPFS = os.path.join(WORK, "tmpfs")
if mount_tmpfs(TMPFS, "size=600k"):
    print("case: full disk on a 600 KiB tmpfs (ENOSPC)")
    filler = os.path.join(TMPFS, "filler")

    def squeeze(n):
        if os.path.exists(filler):
            os.remove(filler)
        if n is not None:
            fill(TMPFS, n)

    full_disk_cases(TMPFS, "tmpfs", None, ["No space left on device"], squeeze)
else:
    print("SKIP: full disk on a tmpfs: mounting is not permitted here "
          "(the RLIMIT_FSIZE case above covers the failing writes)")

# ---- an unwritable folder ------------------------------------------------------------

RO = os.path.join(WORK, "readonly")
how = None
if mount_tmpfs(RO, "size=64k,ro"):
    how, oserr = "read-only tmpfs", ["Read-only file system"]
elif os.geteuid() != 0:
    os.makedirs(RO, exist_ok=True)
    os.chmod(RO, 0o555)
    how, oserr = "chmod 0555", ["Permission denied"]
if how:
    print(f"case: unwritable folder ({how})")
    for args, name in ((["render", VOL, "--size", "32x32", "-o", f"{RO}/a.png"], f"{RO}/a.png"),
                       (POP + ["--report", f"{RO}"], RO),
                       (["render", VOL, "--size", "32x32", "-o", f"{WORK}/ok.png",
                         "--write-scene", f"{RO}/scene.json"], f"{RO}/scene.json")):
        rc, _, err = run(args)
        # The scene is checked before rendering (exit 1 or 2 is a refusal either way).
        if args[-2] == "--write-scene":
            check(rc in (1, 2) and len(err.strip().splitlines()) == 1 and name in err,
                  f"unwritable --write-scene: {rc} {err}")
        else:
            check_error(rc, err, f"unwritable ({how}) {args[0]}", name, oserr)
    check(os.listdir(RO) == [], f"unwritable: files appeared in {RO}")
else:
    print("SKIP: unwritable folder: root, and mounting a read-only tmpfs is not permitted "
          "(root writes through folder permissions)")

# ---- files that disappear or are damaged between a run and --resume ---------------------

print("case: frames deleted, truncated and emptied before --resume")
turn = os.path.join(WORK, "damaged")
ref = clean_run(ROT + ["-o", turn], turn)
rc, _, err = run(ROT + ["-o", turn])
os.remove(f"{turn}/frame_0003.png")
with open(f"{turn}/frame_0005.png", "r+b") as f:
    f.truncate(os.path.getsize(f"{turn}/frame_0005.png") // 2)
open(f"{turn}/frame_0007.png", "wb").close()
with open(f"{turn}/frame_0009.png", "r+b") as f:  # a flipped byte inside the image data
    f.seek(os.path.getsize(f"{turn}/frame_0009.png") // 2)
    b = f.read(1)
    f.seek(-1, 1)
    f.write(bytes([b[0] ^ 0xFF]))
rc, out, err = run(ROT + ["-o", turn, "--resume"])
check(rc == 0, f"damaged frames --resume: {err}")
check("wrote 4 frames" in out, f"damaged frames --resume: expected 4 frames rendered: {out}")
check(state(turn) == ref, "damaged frames --resume: not byte-identical to a clean run")

# ---- an external writer (ffmpeg) that fails --------------------------------------------

print("case: ffmpeg that fails part way, and one that writes nothing")
fake = os.path.join(WORK, "fakebin")
os.makedirs(fake)
for kind, body in (("partial", 'printf partial > "${@: -1}"; '
                               'echo "av_interleaved_write_frame(): No space left on device" >&2; '
                               'exit 1'),
                   ("empty", ': > "${@: -1}"; exit 0')):
    with open(f"{fake}/ffmpeg", "w") as f:
        f.write("#!/bin/bash\n" + body + "\n")
    os.chmod(f"{fake}/ffmpeg", 0o755)
    mp4 = os.path.join(WORK, f"{kind}.mp4")
    with open(mp4, "wb") as f:
        f.write(b"previous video")
    env = dict(os.environ, PATH=fake + ":" + os.environ.get("PATH", ""))
    rc, _, err = run(ROT + ["-o", f"{WORK}/mp4_{kind}", "--mp4", mp4], env=env)
    check_error(rc, err, f"ffmpeg {kind}", mp4,
                ["No space left on device"] if kind == "partial" else ["empty file"])
    with open(mp4, "rb") as f:
        check(f.read() == b"previous video", f"ffmpeg {kind}: previous MP4 changed")
    check_clean(WORK + "/mp4_" + kind, f"ffmpeg {kind}")
    check(not [n for n in os.listdir(WORK) if TEMP.match(n)], f"ffmpeg {kind}: temporary left")

# ---- SIGKILL / SIGINT at random moments, then the same command again ---------------------


def kill_at_random(args, seconds, sig):
    p = subprocess.Popen([SPLAT] + args, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                         text=True)
    time.sleep(seconds)
    p.send_signal(sig)
    _, err = p.communicate(timeout=120)
    return p.returncode, err


def timed(args, out):
    os.makedirs(out, exist_ok=True)
    t = time.time()
    rc, _, err = run(args)
    check(rc == 0, f"timing run {args[0]}: {err}")
    return time.time() - t


SIGNALS = (signal.SIGKILL, signal.SIGINT)
for name, make, compare in (
        ("render", lambda o: ["render", VOL, "--size", "200x200", "-o", f"{o}/a.png"],
         lambda o, ref: state(o) == ref),
        ("rotate", lambda o: ROT + ["-o", o], lambda o, ref: state(o) == ref),
        ("popping", lambda o: POP + ["--report", o],
         lambda o, ref: md5(f"{o}/metrics.csv") == md5(f"{REF}/pop/metrics.csv")),
        ("study", lambda o: STUDY + ["--report", o],
         lambda o, ref: study_accuracy(o) == study_accuracy(f"{REF}/study"))):
    span = timed(make(os.path.join(WORK, f"time_{name}")), os.path.join(WORK, f"time_{name}"))
    for i, sig in enumerate(SIGNALS * 2):
        o = os.path.join(WORK, f"kill_{name}_{i}")
        ref = clean_run(make(o), o)
        os.makedirs(o)
        if name == "render":  # a previous picture that must survive
            shutil.copy(f"{REF}/small.png", f"{o}/a.png")
        at = rng.uniform(0.0, span)
        rc, err = kill_at_random(make(o), at, sig)
        case = f"{name} {signal.Signals(sig).name} at {at:.3f} s"
        print(f"case: {case} -> status {rc}")
        if sig == signal.SIGKILL:
            check(rc in (0, -signal.SIGKILL), f"{case}: status {rc}")
        else:
            lines = err.strip().splitlines()
            # Finished, stopped cleanly (one line), or stopped by the signal's default
            # action before the command installed its handler (before any output).
            check(rc in (0, -signal.SIGINT) or
                  (rc == 1 and len(lines) == 1 and "interrupted" in lines[0]),
                  f"{case}: status {rc}, error {lines}")
        check_clean(o, case, temporaries_ok=True)  # hidden temporaries of a killed run
        if name == "render":
            check(md5(f"{o}/a.png") in (md5(f"{REF}/small.png"), ref.get("a.png")),
                  f"{case}: the picture is neither the previous one nor the new one")
        if name == "rotate":
            s = state(o)
            check(all(ref.get(k) == v for k, v in s.items() if not TEMP.match(k)),
                  f"{case}: a file differs from the clean run")
        again = make(o) + (["--resume"] if name != "render" else [])
        rc, _, err = run(again)
        check(rc == 0, f"{case}, then again: {err}")
        check(compare(o, ref), f"{case}, then again: outputs differ from the clean run")
        check_clean(o, f"{case}, then again")
        check(not os.path.exists(f"{o}/.frames") and not os.path.exists(f"{o}/.points"),
              f"{case}, then again: the journal was not removed")

unmount()
if not failures:
    shutil.rmtree(WORK, ignore_errors=True)
print(f"{len(failures)} failures" if failures else "all fault-injection cases passed")
sys.exit(1 if failures else 0)
