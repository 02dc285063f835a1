"""Shared fixtures. The public ADF corpus lives in ../shared/corpus (never copied here);
tests that need it skip with a clear reason when it is absent."""
from __future__ import annotations

import os
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
CORPUS = Path(os.environ.get("ADFKIT_CORPUS", ROOT.parent / "shared" / "corpus")).resolve()
SKIP_CORPUS = "the public ADF corpus (../shared/corpus) is not present beside this checkout"


def corpus_files(pattern: str = "**/*.yaml") -> list[Path]:
    """Corpus files for parametrisation (empty list when the corpus is absent)."""
    if not CORPUS.is_dir():
        return []
    return sorted(p for p in CORPUS.glob(pattern) if p.is_file())


def corpus_id(p: Path) -> str:
    return str(p.relative_to(CORPUS))


@pytest.fixture(scope="session")
def corpus() -> Path:
    if not CORPUS.is_dir():
        pytest.skip(SKIP_CORPUS)
    return CORPUS


def require_corpus() -> None:
    if not CORPUS.is_dir():
        pytest.skip(SKIP_CORPUS)
