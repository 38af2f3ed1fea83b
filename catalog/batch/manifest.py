"""The output folder's record of what is done: ``manifest.json`` and its journal.

- ``manifest.json``: ``{"schema", "job", "images": [...], "failed": {...}, "summary"}``,
  one record per image (path relative to the folder, fabric, light, frame, yaw, the input
  key, the file's SHA-256 and size), written atomically at the end of a run and every
  minute or so during it.
- ``manifest.journal.jsonl``: one line per image finished since the manifest was last
  written, appended and fsynced as results arrive; replayed (a torn last line ignored) when
  the next run loads the manifest, and removed once the manifest holds its records.
- ``.render-catalog.lock``: held (``flock``) while a run writes the folder; a second run
  on the same folder is refused. The kernel drops it when the holder dies.

An image counts as done when its record has the key the job asks for and its file is
there with the recorded size; a run after a crash renders only the rest.
"""

from __future__ import annotations

import contextlib
import json
import os
from pathlib import Path

from catalog.core.errors import CatalogError

SCHEMA = 1
MANIFEST = "manifest.json"
JOURNAL = "manifest.journal.jsonl"
LOCK = ".render-catalog.lock"


class Manifest:
    def __init__(self, out_dir: Path):
        self.out_dir = Path(out_dir)
        self.path = self.out_dir / MANIFEST
        self.journal_path = self.out_dir / JOURNAL
        self.images: dict[str, dict] = {}
        self.failed: dict[str, str] = {}
        self._journal = None
        self._lock = None

    # ------------------------------------------------------------------ life cycle
    def open(self) -> "Manifest":
        """Take the folder's lock, load what earlier runs recorded, remove their temporary
        image files, and open the journal for appending."""
        import fcntl  # noqa: PLC0415

        self.out_dir.mkdir(parents=True, exist_ok=True)
        self._lock = open(self.out_dir / LOCK, "a+")  # noqa: SIM115
        try:
            fcntl.flock(self._lock.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            self._lock.close()
            self._lock = None
            raise CatalogError(f"{self.out_dir}: another render-catalog is writing this "
                               f"folder") from None
        self._load()
        self._remove_parts()
        self._journal = open(self.journal_path, "a", encoding="utf-8")  # noqa: SIM115
        return self

    def close(self) -> None:
        if self._journal is not None:
            empty = self._journal.tell() == 0
            self._journal.close()
            self._journal = None
            if empty:  # everything is in manifest.json
                self.journal_path.unlink(missing_ok=True)
        if self._lock is not None:
            self._lock.close()
            self._lock = None

    def _load(self) -> None:
        if self.path.exists():
            try:
                doc = json.loads(self.path.read_text(encoding="utf-8"))
                self.images = {rec["path"]: rec for rec in doc.get("images", [])}
                self.failed = dict(doc.get("failed", {}))
            except (ValueError, KeyError, TypeError, AttributeError) as exc:
                raise CatalogError(f"{self.path}: not a render-catalog manifest ({exc}); "
                                   f"move it away to start afresh") from None
        if self.journal_path.exists():
            with open(self.journal_path, encoding="utf-8") as handle:
                for line in handle:
                    try:
                        record = json.loads(line)
                        self.images[record["path"]] = record
                    except (ValueError, KeyError, TypeError):
                        continue  # a line torn by a crash: its image is checked again

    def _remove_parts(self) -> None:
        """Temporary images a killed run left (the output layer's ``.NAME.catalog-tmp-PID-*``
        of a process that is gone), in the folder and each fabric's sub-folder."""
        from catalog.core.atomic import remove_stale_temporaries  # noqa: PLC0415

        for folder in [self.out_dir, *(p for p in self.out_dir.iterdir() if p.is_dir())]:
            remove_stale_temporaries(folder)

    # ------------------------------------------------------------------ queries
    def is_done(self, image) -> bool:
        record = self.images.get(image.path)
        if record is None or record.get("key") != image.key:
            return False
        try:
            return (self.out_dir / image.path).stat().st_size == record.get("bytes")
        except FileNotFoundError:
            return False

    # ------------------------------------------------------------------ updates
    def add(self, records: list[dict]) -> None:
        """Record finished images: into memory and the journal (fsynced)."""
        if not records:
            return
        lines = []
        for record in records:
            record = {k: v for k, v in record.items() if k != "status"}
            self.images[record["path"]] = record
            lines.append(json.dumps(record, sort_keys=True) + "\n")
        self._journal.write("".join(lines))
        self._journal.flush()
        os.fsync(self._journal.fileno())

    def write(self, job: dict, summary: dict | None = None) -> None:
        """Write manifest.json atomically with every record, then empty the journal."""
        from catalog.core.atomic import atomic_path  # noqa: PLC0415

        doc = {"schema": SCHEMA, "job": job,
               "images": [self.images[path] for path in sorted(self.images)],
               "failed": dict(sorted(self.failed.items()))}
        if summary is not None:
            doc["summary"] = summary
        with atomic_path(self.path) as tmp:
            with open(tmp, "w", encoding="utf-8") as handle:
                json.dump(doc, handle, indent=1, sort_keys=False)
                handle.write("\n")
                handle.flush()
                os.fsync(handle.fileno())
        self._journal.truncate(0)
        self._journal.seek(0)
        self._journal.flush()
        os.fsync(self._journal.fileno())
