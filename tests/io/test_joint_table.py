"""occupose.io.joint_table: the one reader and writer of groundtruth.csv and tracks.csv."""

import numpy as np
import pytest

from occupose.io.joint_table import (
    GROUNDTRUTH_COLUMNS,
    TRACKS_COLUMNS,
    JointTableError,
    UnmarkedTableWarning,
    read_joint_table,
    read_tracks_csv,
    write_joint_table,
    write_tracks_csv,
)


def _table():
    """Two frames, tracks 4 and 2 (given out of order), values that exercise the rounding."""
    joints = np.full((2, 15, 3), np.nan)
    joints[0, 0] = [1.25, -0.0000004, 2.0000005]
    joints[0, 2] = [-1.5, 0.1234565, 3.0]
    joints[1, 0] = [0.5, 1e-7, -12.3456789]
    other = np.full((2, 15, 3), np.nan)
    other[1, 14] = [0.0, -0.0, 0.999999951]
    visible = np.zeros((2, 15), bool)
    visible[0, 0] = True
    return {4: (joints, visible), 2: (other, np.ones((2, 15), bool))}


# The bytes the writers wrote before there was one module (metrics.write_tracks_csv and
# RecordingWriter.write_groundtruth at 6b268f5) for _table(): rows by frame, then id, then
# joint; 6 decimals for tracks, 5 for ground truth; "\n" line ends; since issue 26 tracks
# end with the number of rows.
GOLDEN_TRACKS = (
    "frame,track,joint,x,y,z,visible\n"
    "0,4,head,1.250000,-0.000000,2.000001,1\n"
    "0,4,pelvis,-1.500000,0.123456,3.000000,0\n"
    "1,2,right_ankle,0.000000,-0.000000,1.000000,1\n"
    "1,4,head,0.500000,0.000000,-12.345679,0\n"
    "# end: 4 rows\n"
)
GOLDEN_GROUNDTRUTH = (
    "frame,person,joint,x,y,z,visible\n"
    "0,4,head,1.25000,-0.00000,2.00000,1\n"
    "0,4,pelvis,-1.50000,0.12346,3.00000,0\n"
    "1,2,right_ankle,0.00000,-0.00000,1.00000,1\n"
    "1,4,head,0.50000,0.00000,-12.34568,0\n"
)


def test_written_bytes_equal_the_golden_files(tmp_path):
    write_tracks_csv(tmp_path / "tracks.csv", _table())
    assert (tmp_path / "tracks.csv").read_bytes() == GOLDEN_TRACKS.encode()
    write_joint_table(tmp_path / "groundtruth.csv", _table(), "groundtruth")
    assert (tmp_path / "groundtruth.csv").read_bytes() == GOLDEN_GROUNDTRUTH.encode()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["groundtruth.csv", "tracks.csv"]  # no temporary left
    assert GROUNDTRUTH_COLUMNS[1] == "person" and TRACKS_COLUMNS[1] == "track"


@pytest.mark.parametrize("kind", ["tracks", "groundtruth"])
def test_round_trip(tmp_path, rng, kind):
    joints = rng.uniform(-3, 3, size=(4, 15, 3))
    joints[:, 9:] = np.nan
    joints[2] = np.nan
    visible = rng.random((4, 15)) < 0.5
    other = rng.uniform(-3, 3, size=(4, 15, 3))
    path = tmp_path / f"{kind}.csv"
    write_joint_table(path, {12: (joints, visible), 3: (other, np.ones((4, 15), bool))}, kind)
    lines = path.read_text().splitlines()
    assert lines[0] == f"frame,{'track' if kind == 'tracks' else 'person'},joint,x,y,z,visible"
    assert lines[1].startswith("0,3,head,")  # frame, then id, then joint order
    assert len(lines) == 1 + 4 * 15 + 3 * 9 + (kind == "tracks")
    if kind == "tracks":
        assert lines[-1] == f"# end: {4 * 15 + 3 * 9} rows"

    table = read_joint_table(path, 4, kind)
    assert list(table) == [3, 12]  # in the order of their first row
    tolerance = 5e-7 if kind == "tracks" else 5e-6
    read_joints, read_visible = table[12]
    np.testing.assert_allclose(read_joints, joints, rtol=0, atol=tolerance)  # NaN positions match too
    assert np.array_equal(read_visible, visible & np.isfinite(joints).all(axis=2))
    np.testing.assert_allclose(table[3][0], other, rtol=0, atol=tolerance)
    assert table[3][1].all()
    # written again, the read table gives the same bytes
    write_joint_table(tmp_path / "again.csv", table, kind)
    assert (tmp_path / "again.csv").read_bytes() == path.read_bytes()


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("", r"bad_tracks.csv: bad header \[\] \(an empty file\); expected columns frame,track,joint,x,y,z,visible$"),
        ("frame,track,joint,x,y,z\n", r"bad_tracks.csv: bad header \['frame', 'track', 'joint', 'x', 'y', 'z'\]"),
        ("frame,person,joint,x,y,z,visible\n", r"bad header \['frame', 'person', "),
        ("frame,track,joint,x,y,z,visible\n0,1,nose,0,0,0,1\n",
         "bad_tracks.csv, line 2: unknown joint 'nose'; valid joints: head, neck, pelvis"),
        ("frame,track,joint,x,y,z,visible\n0,1,head,0,abc,0,1\n", "bad_tracks.csv, line 2: y must be a number, got 'abc'"),
        ("frame,track,joint,x,y,z,visible\n0,1,head,0,inf,0,1\n", "bad_tracks.csv, line 2: y must be finite, got 'inf'"),
        ("frame,track,joint,x,y,z,visible\n0,1,head,0,0,1\n",
         r"bad_tracks.csv, line 2: expected 7 columns, got 6: \['0', '1', 'head', '0', '0', '1'\]"),
        ("frame,track,joint,x,y,z,visible\n0.5,1,head,0,0,0,1\n", "bad_tracks.csv, line 2: frame must be an integer, got '0.5'"),
        ("frame,track,joint,x,y,z,visible\n0,one,head,0,0,0,1\n", "bad_tracks.csv, line 2: track must be an integer, got 'one'"),
        ("frame,track,joint,x,y,z,visible\n\n7,1,head,0,0,0,1\n",
         r"bad_tracks.csv, line 3: frame 7 out of range; the recording has frames 0..4"),
        ("frame,track,joint,x,y,z,visible\n0,1,head,0,0,0,2\n", "bad_tracks.csv, line 2: visible must be 0 or 1, got '2'"),
        ("frame,track,joint,x,y,z,visible\n0,1,head,0,0,0,1\n0,1,head,1,0,0,1\n",
         "bad_tracks.csv, line 3: duplicate row for frame 0, track 1, joint head"),
        pytest.param("frame,track,joint,x,y,z,visible\n0,1,head," + "9" * 200_000 + ",0,0,1\n",
                     r"bad_tracks.csv, line 2: not a readable UTF-8 CSV file \(field larger than field limit",
                     id="csv-error"),
    ],
)
def test_a_malformed_file_is_an_error_naming_file_and_line(tmp_path, text, message):
    path = tmp_path / "bad_tracks.csv"
    path.write_text(text)
    with pytest.raises(JointTableError, match=message) as info:
        read_tracks_csv(path, num_frames=5)
    assert str(path) in str(info.value) and isinstance(info.value, ValueError)


def test_not_utf8_is_an_error_naming_the_file(tmp_path):
    path = tmp_path / "tracks.csv"
    path.write_bytes(b"frame,track,joint,x,y,z,visible\n\xff\xfe\n")
    with pytest.raises(JointTableError, match=r"tracks.csv: not a readable UTF-8 CSV file \(invalid start byte at byte 32\)"):
        read_tracks_csv(path, 5)


def test_a_tracks_file_cut_short_or_with_rows_lost_is_refused(tmp_path):
    path = tmp_path / "tracks.csv"
    write_tracks_csv(path, _table())
    lines = path.read_text().splitlines(keepends=True)
    cut = tmp_path / "cut.csv"
    cut.write_text("".join(lines[:3]))  # at a line boundary: header and 2 of the 4 rows
    with pytest.raises(JointTableError, match=r"cut.csv: no end line \('# end: 2 rows'\) after its 2 rows"):
        read_tracks_csv(cut, 2)
    with pytest.warns(UnmarkedTableWarning, match="cut.csv: no end line"):
        table = read_tracks_csv(cut, 2, allow_unmarked=True)
    assert list(table) == [4] and np.isfinite(table[4][0][..., 0]).sum() == 2
    gap = tmp_path / "gap.csv"
    gap.write_text("".join(lines[:2] + lines[3:]))  # the end line kept, a row lost
    with pytest.raises(JointTableError, match="gap.csv: its end line says 4 rows, the file has 3"):
        read_tracks_csv(gap, 2, allow_unmarked=True)
    after = tmp_path / "after.csv"
    after.write_text("".join(lines + lines[1:2]))
    with pytest.raises(JointTableError, match="after.csv, line 7: text after the end line"):
        read_tracks_csv(after, 2)
    comment = tmp_path / "comment.csv"
    comment.write_text("".join(lines[:2] + ["# made by hand\n"] + lines[2:]))
    with pytest.raises(JointTableError, match=r"comment.csv, line 3: a comment line; the only one allowed is the last"):
        read_tracks_csv(comment, 2)


def test_ground_truth_needs_no_end_line_but_one_is_checked(tmp_path):
    path = tmp_path / "groundtruth.csv"
    write_joint_table(path, _table(), "groundtruth")
    assert not path.read_text().startswith("#") and "#" not in path.read_text()
    assert len(read_joint_table(path, 2, "groundtruth")) == 2
    path.write_text(path.read_text() + "# end: 5 rows\n")
    with pytest.raises(JointTableError, match="its end line says 5 rows, the file has 4"):
        read_joint_table(path, 2, "groundtruth")


def test_a_byte_order_mark_and_crlf_line_ends_are_read(tmp_path):
    path = tmp_path / "tracks.csv"
    write_tracks_csv(path, _table())
    expected = read_tracks_csv(path, 2)
    path.write_bytes(b"\xef\xbb\xbf" + path.read_bytes().replace(b"\n", b"\r\n"))
    table = read_tracks_csv(path, 2)
    assert list(table) == list(expected)
    for ident in table:
        np.testing.assert_array_equal(table[ident][0], expected[ident][0])
        np.testing.assert_array_equal(table[ident][1], expected[ident][1])


def test_a_folder_or_a_device_is_an_error_naming_it(tmp_path):
    (tmp_path / "tracks.csv").mkdir()
    with pytest.raises(JointTableError, match="tracks.csv: is a folder; expected a tracks CSV file"):
        read_tracks_csv(tmp_path / "tracks.csv", 2)
    with pytest.raises(JointTableError, match="/dev/zero: is a device, pipe or socket; expected a tracks CSV file"):
        read_tracks_csv("/dev/zero", 2)


def test_visible_column_is_optional_in_ground_truth_only(tmp_path):
    path = tmp_path / "groundtruth.csv"
    path.write_text("frame,person,joint,x,y,z\n1,4,neck,0.1,0.2,1.5\n")
    (joints, visible), = read_joint_table(path, 3, "groundtruth").values()
    assert visible.sum() == 1 and visible[1, 1] and np.isfinite(joints).sum() == 3
    with pytest.raises(JointTableError, match=r"expected columns frame,track,joint,x,y,z,visible$"):
        read_joint_table(path.rename(tmp_path / "tracks.csv"), 3, "tracks")


def test_missing_file_empty_table_and_bad_arguments(tmp_path):
    with pytest.raises(FileNotFoundError, match="nothing.csv: no such tracks file"):
        read_tracks_csv(tmp_path / "nothing.csv", num_frames=5)
    path = tmp_path / "tracks.csv"
    write_tracks_csv(path, {})
    assert path.read_text() == "frame,track,joint,x,y,z,visible\n# end: 0 rows\n"
    assert read_tracks_csv(path, num_frames=5) == {}
    with pytest.raises(ValueError, match="num_frames must be an integer >= 0, got -1"):
        read_tracks_csv(path, num_frames=-1)
    with pytest.raises(ValueError, match="unknown joint table kind 'bvh'; valid: groundtruth, tracks"):
        read_joint_table(path, 5, "bvh")


def test_the_writer_checks_its_input(tmp_path):
    joints = np.zeros((2, 15, 3))
    visible = np.ones((2, 15), dtype=bool)
    path = tmp_path / "t.csv"
    with pytest.raises(ValueError, match="every track must have the same number of frames, got 2 and 1"):
        write_tracks_csv(path, {1: (joints, visible), 2: (joints[:1], visible[:1])})
    with pytest.raises(ValueError, match="track ids must be integers, got 'a'"):
        write_tracks_csv(path, {"a": (joints, visible)})
    with pytest.raises(ValueError, match="person ids must be integers, got True"):
        write_joint_table(path, {True: (joints, visible)}, "groundtruth")
    with pytest.raises(ValueError, match=r"track 1 joints must have shape \(N, 15, 3\)"):
        write_tracks_csv(path, {1: (joints[:, :9], visible)})
    with pytest.raises(ValueError, match="track 1 visible must be a boolean array"):
        write_tracks_csv(path, {1: (joints, visible.astype(int))})
    with pytest.raises(ValueError, match=r"track 1: expected a \(joints, visible\) pair, got list"):
        write_tracks_csv(path, {1: [joints, visible]})
    partial = joints.copy()
    partial[0, 3, 1] = np.nan
    with pytest.raises(ValueError, match="track 1 joints must be fully finite or fully NaN per joint"):
        write_tracks_csv(path, {1: (partial, visible)})
    with pytest.raises(ValueError, match="fully finite or fully NaN"):
        write_tracks_csv(path, {1: (joints + np.inf, visible)})
    assert not path.exists()
