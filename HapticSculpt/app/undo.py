"""One undo transaction around a block of document edits: committed if the block finishes,
aborted (the document left as it was) if it raises."""
from __future__ import annotations

from contextlib import contextmanager
from typing import Any, Iterator


@contextmanager
def transaction(doc: Any, title: str) -> Iterator[None]:
    """``with transaction(doc, "Sculpt stroke"): ...`` — one entry in the document's undo list."""
    doc.openTransaction(title)
    try:
        yield
    except BaseException:
        doc.abortTransaction()
        raise
    doc.commitTransaction()
