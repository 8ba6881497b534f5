"""A non-editable install must still find the Prolog sources and the calibration maps (shipped inside the
packages)."""

import subprocess
import sys
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def test_wheel_ships_prolog_sources_and_they_are_found_outside_the_checkout(tmp_path):
    wheels = tmp_path / "wheels"
    subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "-q",
                    "-w", str(wheels), str(ROOT)], check=True, capture_output=True)
    (wheel,) = wheels.glob("lv3d-*.whl")
    names = zipfile.ZipFile(wheel).namelist()
    shipped = sorted(n for n in names if n.startswith("prolog/") and n.endswith(".pl"))
    checkout = sorted(str(p.relative_to(ROOT)) for p in (ROOT / "prolog").rglob("*.pl"))
    assert shipped == checkout, f"wheel ships {shipped}, checkout has {checkout}"
    assert "lv3d/data/calibration.json" in names
    site = tmp_path / "site"
    subprocess.run([sys.executable, "-m", "pip", "install", "--no-deps", "-q", "--target", str(site), str(wheel)],
                   check=True, capture_output=True)
    probe = ("import prolog, lv3d, pathlib; "
             "assert pathlib.Path(prolog.__file__).is_relative_to(pathlib.Path(r'%s')), prolog.__file__; "
             "import lv3d.calibration; assert lv3d.calibration.read()['table']; "
             "print(len([p for p in pathlib.Path(prolog.__file__).parent.rglob('*.pl')]))" % site)
    out = subprocess.run([sys.executable, "-c", probe], cwd=tmp_path, env={"PYTHONPATH": str(site)},
                         check=True, capture_output=True, text=True)
    assert int(out.stdout.strip()) == len(checkout)
