"""Writes gfs_eccodes.csv: ecCodes' decode of weather/gfs-2011-01-10T12Z-f120-2p5deg.grib2 at 24
grid points of 12 fields, the reference src/weather/model/tests.rs checks skycast's decoder
against.

Made with ecCodes 2.x from PyPI (`pip install eccodes`), from the repository root:
    python3 tests/weather/model/gfs_eccodes.py > tests/weather/model/gfs_eccodes.csv
Multi-field support is on, so the v wind NCEP sends in the u message's second field is read too.
"""
import eccodes

PATH = "weather/gfs-2011-01-10T12Z-f120-2p5deg.grib2"
# (shortName, typeOfFirstFixedSurface, level)
WANTED = [
    ("gh", 100, 500), ("t", 100, 850), ("u", 100, 250), ("v", 100, 250), ("r", 100, 700),
    ("tcc", 214, 0), ("tcc", 224, 0), ("tcc", 234, 0), ("avg_pres", 212, 0),
    ("orog", 1, 0), ("cape", 1, 0), ("prate", 1, 0),
]
# 24 grid points spread over the globe (a fixed stride through the 144 x 73 grid).
POINTS = [(k * 4391 + 57) % (144 * 73) for k in range(24)]

eccodes.codes_grib_multi_support_on()
print("short_name,discipline,category,number,surface_type,surface_value,index,lat_deg,lon_deg,value")
with open(PATH, "rb") as f:
    while True:
        h = eccodes.codes_grib_new_from_file(f)
        if h is None:
            break
        g = lambda k: eccodes.codes_get(h, k)
        key = (g("shortName"), eccodes.codes_get_long(h, "typeOfFirstFixedSurface"), g("level"))
        if key in WANTED:
            values = eccodes.codes_get_values(h)
            missing = g("missingValue")
            lats = eccodes.codes_get_array(h, "latitudes")
            lons = eccodes.codes_get_array(h, "longitudes")
            # The surface value as GRIB scales it (Pa for isobaric levels).
            sv = eccodes.codes_get_double(h, "scaledValueOfFirstFixedSurface")
            sf = eccodes.codes_get_long(h, "scaleFactorOfFirstFixedSurface")
            surface_value = 0 if sf < -100 or sv > 1e9 else sv / 10 ** sf
            for i in POINTS:
                bitmap = g("bitmapPresent")
                value = "missing" if bitmap and values[i] == missing else repr(float(values[i]))
                print(f"{key[0]},{g('discipline')},{g('parameterCategory')},{g('parameterNumber')},"
                      f"{key[1]},{surface_value:g},{i},{lats[i]:g},{lons[i]:g},{value}")
            WANTED.remove(key)
        eccodes.codes_release(h)
assert not WANTED, f"not found: {WANTED}"
