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


#: BLAKE3 digests of b"" and b"abc" from the official test vectors of the BLAKE3 reference
#: implementation (github.com/BLAKE3-team/BLAKE3, test_vectors.json and the spec's examples).
BLAKE3_EMPTY = "af1349b9f5f9a1a6a0404dea36dcc9499bcb25c9adc112b7cc9a93cae41f3262"
BLAKE3_ABC = "6437b3ac38465133ffb63b75273a8db548c558465d79db03fd359c6cd5bd9d85"


#: XXH3-128 (seed 0) of b"": the length-0 entry of xxHash's tests/sanity_test_vectors.h (github.com/Cyan4973/xxHash);
#: of b"abc": the value the xxhash-rust crate's tests and an independent Haxe port lock (found by searching their
#: sources for the empty vector).
XXH3_128_EMPTY = "99aa06d3014798d86001c324468d497f"
XXH3_128_ABC = "06b05ab6733a618578af5f94892f3950"


@pytest.mark.parametrize(("algorithm", "abc", "empty", "other", "other_abc"), [
    ("blake3", BLAKE3_ABC, BLAKE3_EMPTY, "sha256", SHA256_ABC),
    ("xxh3_128", XXH3_128_ABC, XXH3_128_EMPTY, "blake3", BLAKE3_ABC),
])
def test_hashes_match_their_reference_vectors(tmp_path, algorithm, abc, empty, other, other_abc):
    from cageless.provenance import hash_file

    p = tmp_path / "abc.bin"
    p.write_bytes(b"abc")
    assert hash_file(p, algorithm, cache=False) == abc
    assert hash_file(p, algorithm) == abc and hash_file(p, algorithm) == abc  # cached
    assert hash_file(p, other) == other_abc  # a separate cache per algorithm
    (tmp_path / "empty.bin").write_bytes(b"")
    assert hash_file(tmp_path / "empty.bin", algorithm, cache=False) == empty


def test_videos_are_hashed_with_xxh3_and_unknown_algorithms_are_refused(tmp_path):
    from cageless.provenance import VIDEO_HASH, hash_file

    assert VIDEO_HASH == "xxh3_128"
    (tmp_path / "abc.bin").write_bytes(b"abc")
    with pytest.raises(ValueError, match="md5"):
        hash_file(tmp_path / "abc.bin", "md5")


def test_provenance_names_the_hash_algorithm(tmp_path):
    from cageless.provenance import InputFile

    p = tmp_path / "in.cine"
    p.write_bytes(b"abc")
    d = Provenance.start(inputs=[p], background=True, hash_algorithm="blake3").finish().to_dict()
    assert d["inputs"] == [{"name": str(p), "size_bytes": 3, "blake3": BLAKE3_ABC}]
    back = InputFile.from_dict(d["inputs"][0])
    assert (back.algorithm, back.digest, back.sha256) == ("blake3", BLAKE3_ABC, None)
    old = InputFile.from_dict({"name": "x", "size_bytes": 3, "sha256": SHA256_ABC})
    assert (old.algorithm, old.sha256) == ("sha256", SHA256_ABC)
    d = Provenance.start(inputs=[p], hash_algorithm="xxh3_128").finish().to_dict()
    assert d["inputs"] == [{"name": str(p), "size_bytes": 3, "xxh3_128": XXH3_128_ABC}]
    assert InputFile.from_dict(d["inputs"][0]).algorithm == "xxh3_128"


def test_prefetched_hash_is_computed_once(tmp_path, monkeypatch):
    import cageless.provenance as pv

    p = tmp_path / "abc.bin"
    p.write_bytes(b"abc")
    calls = []
    real = pv._hash_uncached
    monkeypatch.setattr(pv, "_hash_uncached", lambda path, alg: calls.append(alg) or real(path, alg))
    pv.prefetch_hash(p, "blake3")
    pv.prefetch_hash(p, "blake3")  # already running or cached: no second job
    assert pv.hash_file(p, "blake3") == BLAKE3_ABC
    assert pv.hash_file(p, "blake3") == BLAKE3_ABC
    assert calls == ["blake3"]
