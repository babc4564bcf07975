"""Each released stroke kept for FreeCAD's document recovery (GUI only).

FreeCAD's AutoSaver writes a document's recovery file on a timer (every 15 minutes by default), so
strokes released since its last write were lost when FreeCAD was killed. After each commit a
session makes, once FreeCAD's event loop is idle again (the commit's transaction closed), this
writes the same two files the AutoSaver writes into the document's transient folder:
``fc_recovery_file.fcstd`` (the document as its compressed recovery file holds it) and
``fc_recovery_file.xml`` (status, label and file name). At the next start FreeCAD's own Document
Recovery finds them, as it finds the AutoSaver's, for a saved document and for one never saved.

The file is written whole, in a few milliseconds for a sculpt (bench/recovery_save.py), on the GUI
thread, where FreeCAD's documents may be read; the haptic and simulation loops run on their own
threads and do not wait for it. Commits closer together than one idle pass share one write.
"""
from __future__ import annotations

import os
import time
from typing import Any
from xml.sax.saxutils import escape

#: Parameter group of FreeCAD's document preferences (its thumbnail setting is switched off while
#: writing, as the AutoSaver does: a thumbnail renders the 3D view, slow and not needed to recover).
DOCUMENT_PREFERENCES = "User parameter:BaseApp/Preferences/Document"


class RecoveryWriter:
    """Writes the recovery files of the documents whose sessions committed, once idle."""

    def __init__(self) -> None:
        self._pending: set[str] = set()
        self._sensor: Any = None
        #: Per document name: the writes made, the seconds the last one took (what a release
        #: costs) and the undo steps the file holds.
        self.written: dict[str, dict[str, float]] = {}

    def committed(self, obj: Any, *_: Any, **__: Any) -> None:
        """A session commit listener: schedules the write of ``obj``'s document for when the event
        loop is idle (called inside the commit's transaction, which is not closed yet)."""
        self._pending.add(obj.Document.Name)
        if self._sensor is None:
            from pivy import coin
            self._sensor = coin.SoOneShotSensor(lambda *_: self.write_pending(), None)
        if not self._sensor.isScheduled():
            self._sensor.schedule()

    @property
    def pending(self) -> bool:
        """Whether a commit's recovery file is still to be written."""
        return bool(self._pending)

    def write_pending(self) -> None:
        """Writes the recovery file of every document scheduled (one that closed meanwhile is
        skipped); a failed write is reported and keeps the stroke in the document all the same."""
        import FreeCAD
        names, self._pending = self._pending, set()
        for name in sorted(names):
            doc = FreeCAD.listDocuments().get(name)
            if doc is None:
                continue
            try:
                start = time.perf_counter()
                write(doc)
                last = self.written.get(name, {"writes": 0})
                self.written[name] = {"writes": last["writes"] + 1, "seconds": time.perf_counter() - start,
                                      "undo_steps": len(doc.UndoNames)}
            except Exception as exc:  # noqa: BLE001 - reported: the stroke stays committed
                FreeCAD.Console.PrintWarning(f"HapticSculpt: the recovery file of {doc.Label} was not written: {exc}\n")


def write(doc: Any) -> str:
    """Writes ``doc``'s recovery files into its transient folder, where FreeCAD's AutoSaver writes
    them (the document to a temporary name first, then renamed: a kill mid-write leaves the last
    whole file). Returns the recovery file's path."""
    import FreeCAD
    folder = doc.TransientDir
    path = os.path.join(folder, "fc_recovery_file.fcstd")
    partial = os.path.join(folder, "fc_recovery_file.part.FCStd")  # (saveCopy adds .FCStd to other names)
    preferences = FreeCAD.ParamGet(DOCUMENT_PREFERENCES)
    thumbnail = preferences.GetBool("SaveThumbnail", True)
    preferences.SetBool("SaveThumbnail", False)
    try:
        doc.saveCopy(partial)
    finally:
        preferences.SetBool("SaveThumbnail", thumbnail)
    os.replace(partial, path)
    meta = (f"<?xml version='1.0' encoding='utf-8'?>\n<AutoRecovery SchemaVersion=\"1\">\n"
            f"  <Status>Created</Status>\n  <Label>{escape(doc.Label)}</Label>\n"
            f"  <FileName>{escape(doc.FileName)}</FileName>\n</AutoRecovery>\n")
    with open(os.path.join(folder, "fc_recovery_file.xml"), "w", encoding="utf-8") as f:
        f.write(meta)
    return path
