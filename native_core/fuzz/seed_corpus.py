#!/usr/bin/env python3
"""Seed corpora for the fuzz harnesses: from hid-recorder fixtures, the recordings themselves
(fuzz_hid_recording), their report descriptors (fuzz_report_descriptor) and their input reports,
each prefixed with its length as the harness reads them (fuzz_spacemouse_report); the Falcon's
status stream (fuzz_falcon_frames, from ../falcon next to the HID fixtures); the Haply service's
messages (fuzz_haply_messages, from ../haply); and for every harness the inputs that once broke it,
kept by name in findings/HARNESS/ beside this script.

    seed_corpus.py FIXTURE_DIR CORPUS_DIR
"""
from __future__ import annotations

import pathlib
import shutil
import sys


def hex_bytes(fields: list[str]) -> bytes:
    return bytes(int(x, 16) for x in fields)


def main(fixtures: str, corpus: str) -> None:
    out = pathlib.Path(corpus)
    for name in ("fuzz_hid_recording", "fuzz_report_descriptor", "fuzz_spacemouse_report", "fuzz_falcon_frames",
                 "fuzz_haply_messages"):
        (out / name).mkdir(parents=True, exist_ok=True)
    for path in sorted(pathlib.Path(fixtures).parent.joinpath("haply").glob("*.json")):
        shutil.copy(path, out / "fuzz_haply_messages" / path.name)
    for findings in sorted(pathlib.Path(__file__).parent.joinpath("findings").iterdir()):
        for path in sorted(findings.iterdir()):
            shutil.copy(path, out / findings.name / path.name)
    for path in sorted(pathlib.Path(fixtures).parent.joinpath("falcon").glob("*.bin")):
        shutil.copy(path, out / "fuzz_falcon_frames" / path.name)
    for path in sorted(pathlib.Path(fixtures).glob("*.hid")):
        shutil.copy(path, out / "fuzz_hid_recording" / path.name)
        reports = b""
        for line in path.read_text().splitlines():
            tag, _, rest = line.partition(": ")
            fields = rest.split()
            if tag == "R":  # R: length bytes...
                (out / "fuzz_report_descriptor" / f"{path.stem}.bin").write_bytes(hex_bytes(fields[1:]))
            elif tag == "E":  # E: sec.usec length bytes...
                report = hex_bytes(fields[2:])
                reports += bytes([len(report)]) + report
        (out / "fuzz_spacemouse_report" / f"{path.stem}.bin").write_bytes(reports)


if __name__ == "__main__":
    main(*sys.argv[1:3])
