"""Where tests find the repository's files and the team handbook's data."""

from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
CONFIG = REPO / "config"
STATION_FILE = CONFIG / "station.toml"
DBC_FILE = CONFIG / "can" / "station.dbc"
JOINTS = CONFIG / "joints"
JOINT_5_2 = JOINTS / "paper-section-5-2.toml"
#: ../shared beside the checkout (CI puts it there); a bare clone has none.
HANDBOOK_DATA = REPO.parent / "shared" / "data"
#: Four real CS351 runs shipped with the project (both classes; source and licence in
#: its README.md): every test can use them, in a bare clone too.
PROJECT_REAL_RUNS = REPO / "tests" / "data" / "cs351-real-runs"
#: The ten real CS351 runs of the team handbook, a wider check where ../shared is there
#: (tests skip it, with the reason, where it is not).
HANDBOOK_REAL_RUNS = HANDBOOK_DATA / "cs351-real-runs"
