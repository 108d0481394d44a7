"""Provenance records and the atomic writer."""

from __future__ import annotations

import json

import pytest

from cageless import __version__
from cageless.atomic import atomic_path, atomic_write_text
from cageless.provenance import Provenance, git_commit, sha256_file

# FIPS 180-2, appendix B.1: SHA-256("abc").
SHA256_ABC = "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"


def test_sha256_matches_the_fips_test_vector(tmp_path):
    p = tmp_path / "abc.bin"
    p.write_bytes(b"abc")
    assert sha256_file(p) == SHA256_ABC


def test_folder_hash_depends_on_names_and_contents(tmp_path):
    seq = tmp_path / "seq"
    seq.mkdir()
    (seq / "f0.png").write_bytes(b"a")
    (seq / "f1.png").write_bytes(b"b")
    h1 = sha256_file(seq)
    (seq / "f1.png").write_bytes(b"c")
    assert sha256_file(seq) != h1


def test_provenance_record(tmp_path):
    p = tmp_path / "in.cine"
    p.write_bytes(b"abc")
    prov = Provenance.start(config={"rtol": 1e-6}, inputs=[p])
    assert prov.finished_utc is None
    d = prov.finish().to_dict()
    assert d["software_version"] == __version__
    assert d["inputs"] == [{"name": str(p), "size_bytes": 3, "sha256": SHA256_ABC}]
    assert d["config"] == {"rtol": 1e-6}
    assert d["started_utc"] <= d["finished_utc"]
    json.dumps(d)  # JSON-ready
    commit = git_commit()
    assert commit is None or len(commit.removesuffix("-dirty")) == 40


def test_atomic_write_text(tmp_path):
    target = tmp_path / "sub" / "out.txt"
    atomic_write_text(target, "hello")
    assert target.read_text() == "hello"
    with pytest.raises(KeyError), atomic_path(target) as tmp:
        tmp.write_text("half")
        raise KeyError("crash")
    assert target.read_text() == "hello"
    assert [p.name for p in target.parent.iterdir()] == ["out.txt"]


def test_hash_cache_follows_the_file(tmp_path):
    from cageless.provenance import cache_dir

    p = tmp_path / "v.bin"
    p.write_bytes(b"abc")
    assert sha256_file(p) == SHA256_ABC
    assert len(list((cache_dir() / "sha256").iterdir())) == 1
    assert sha256_file(p) == SHA256_ABC  # from the cache
    p.write_bytes(b"abcd")  # new size and mtime: a new key, a fresh hash
    assert sha256_file(p) == "88d4266fd4e6338d13b845fcf289579d209c897823b9217da3e161936f031589"
    assert sha256_file(p, cache=False) == sha256_file(p)
