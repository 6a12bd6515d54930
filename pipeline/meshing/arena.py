"""Reproducible meshes: each made in an allocator arena of its own (`fixed_allocator`)."""

from __future__ import annotations

import ctypes
import queue
import threading


def fixed_allocator() -> None:
    """gmsh hands HXT the surface vertices in the order of their memory addresses (`Gmsh2Hxt`
    collects them in a `std::set<MVertex *>`), and HXT's optimiser decides its ties in that order:
    the same model and size field made 12,228 or 12,229 nodes depending on what the process had
    allocated before (its paths' lengths, earlier meshes), and a fresh clone of the project in
    another folder made another design 5. So every mesh is made in a thread
    of its own (`in_fresh_arena`): glibc gives a new thread a new arena, whose blocks it hands out
    in the order the meshing asks for them, whatever the process did before. Two settings keep it
    so: the size above which a block is mapped on its own is fixed (glibc raises it as mapped
    blocks are freed, so a block could sit in the arena on one run and outside it on another),
    and the number of arenas is raised so that each thread gets a new one. Checked: one process
    meshing the same model 4 times after allocations of 5 sizes, from two folders, 40 of 40
    meshes the same (without: 10 of 40 differ)."""
    try:
        libc = ctypes.CDLL("libc.so.6")
    except OSError:  # not glibc
        return
    m_mmap_threshold, m_arena_max = -3, -8
    libc.mallopt(m_mmap_threshold, 128 * 1024)
    libc.mallopt(m_arena_max, 1024)


def in_fresh_arena(fn, *args):
    """`fn(*args)` in a new thread (a new allocator arena, `fixed_allocator`), which is then
    parked for the rest of the process: an ended thread's arena, with its free blocks, would be
    handed to the next thread. Returns what `fn` returns; raises what it raises."""
    done: dict = {}
    finished = threading.Event()

    def run():
        try:
            done["value"] = fn(*args)
        except BaseException as e:  # noqa: BLE001 - handed to the caller
            done["error"] = e
        finished.set()
        threading.Event().wait()

    threading.Thread(target=run, daemon=True).start()
    finished.wait()
    if "error" in done:
        raise done["error"]
    return done["value"]


class ArenaWorker:
    """One mesh of `serve` in a thread with an arena of its own (`in_fresh_arena`): it first
    runs `prepare` (the next model built while the caller solves the last mesh), then waits for
    the request's work, runs it, and parks."""

    def __init__(self, prepare):
        self.jobs: queue.Queue = queue.Queue()
        self.results: queue.Queue = queue.Queue()
        threading.Thread(target=self._run, args=(prepare,), daemon=True).start()

    def _run(self, prepare) -> None:
        prepare()
        job = self.jobs.get()
        try:
            self.results.put((True, job()))
        except BaseException as e:  # noqa: BLE001 - handed to the caller
            self.results.put((False, e))
        threading.Event().wait()

    def run(self, job):
        self.jobs.put(job)
        ok, value = self.results.get()
        if not ok:
            raise value
        return value
