"""The data-set package (``asp.datasets``, NumPy only): one validated JSONL streamer shared by the
removability and the transitions readers, and the earlier module names ``asp.data``/``asp.qdata``."""

from __future__ import annotations

import pytest

import asp
import asp.data
import asp.qdata
from asp.datasets import DataError, jsonl, removability, transitions
from test_qtrain import small
from test_train_data import write_stacks_dataset


def test_earlier_module_names_re_export_the_readers():
    assert asp.data.RemovabilityDataset is removability.RemovabilityDataset
    assert asp.qdata.TransitionDataset is transitions.TransitionDataset
    assert asp.data.DataError is asp.qdata.DataError is DataError is jsonl.DataError
    for module, new in ((asp.data, removability), (asp.qdata, transitions)):
        for name in module.__all__:
            assert getattr(module, name) is getattr(new, name, getattr(jsonl, name, None)), name
    assert issubclass(DataError, asp.AspError) and issubclass(DataError, ValueError)


def test_stream_skips_blank_lines_and_checks_the_count(tmp_path):
    path = tmp_path / "r.jsonl"
    path.write_text('{"a": 1}\n\n   \n{"a": 2}\n')
    got = list(jsonl.stream_jsonl(path, 2, "record", lambda obj, where: (obj["a"], where)))
    assert got == [(1, f"{path}:1"), (2, f"{path}:4")]
    with pytest.raises(DataError, match=r": has 2 records, index\.json announces 3$"):
        list(jsonl.stream_jsonl(path, 3, "record", lambda obj, where: obj))


@pytest.mark.parametrize(
    "text, message",
    [
        ('{"a": 1}\n{"a": \n', "{path}:2: invalid JSON: Expecting value"),
        ('[1, 2]\n', "{path}:1: a widget must be a JSON object"),
    ],
)
def test_stream_names_file_line_and_record(tmp_path, text, message):
    path = tmp_path / "w.jsonl"
    path.write_text(text)
    with pytest.raises(DataError) as e:
        list(jsonl.stream_jsonl(path, 2, "widget", lambda obj, where: obj))
    assert str(e.value) == message.format(path=path)


def test_stream_is_lazy_about_a_missing_file(tmp_path):
    stream = jsonl.stream_jsonl(tmp_path / "none.jsonl", 0, "record", lambda obj, where: obj)
    with pytest.raises(DataError, match=r"none\.jsonl: file not found$"):
        next(stream)


def test_both_readers_parse_their_lines_through_the_shared_streamer(tmp_path, monkeypatch):
    calls = []
    shared = jsonl.parse_line

    def counting(path, line, lineno, record, parse):
        calls.append(record)
        return shared(path, line, lineno, record, parse)

    monkeypatch.setattr(jsonl, "parse_line", counting)
    states = list(removability.RemovabilityDataset.open(write_stacks_dataset(tmp_path / "r", ["s0"])).states())
    moves = list(transitions.TransitionDataset.open(small(tmp_path / "t")).transitions())
    assert states and moves
    assert calls == ["state"] * len(states) + ["transition"] * len(moves)
