"""pvpython: one table of parameter bounds per core, and everything a user
sees agrees with it. For every row that graupel-params prints (the table the
core's validators follow, gr_<core>_param_bounds):

  * the XML (the plugin's proxy): the default, and the domain. A range domain
    is the slider: its max is the table's max and its min the table's min (or
    above it when the table's min is open), unless the property's hint
    <GraupelRange min max/> declares the slider deliberately narrower: then the
    hint is the table's range and the slider lies inside it. An enumeration
    lists every whole number of the range; a boolean is 0-1.
  * the VTK class: its default, and its clamp: a value just above max reads
    back as max, just below a closed min as min, and just below an open min is
    not moved inside the range (the validator refuses it at the next update).
  * the filter's page docs/<Proxy>.md: every row once in a property table, in this format (columns
    property | default | unit, range | meaning):

        | `RainRate` | 10 | mm/h, 0–3600 | rain intensity ... |
        | `MaxTimeStep` | 3600 | s, (0, 3600] | longest step ... |
        | `Octaves` | 6 | 1–16 | ... |
        | `NoiseType` | Ridged Multifractal (0) | 0–2 | ... |
        | `Seed` | 0 | any | ... |

    default: a number, or a name with its number in parentheses; unit, range:
    the table's unit (none when it has none), a comma, then `min–max` (an en
    dash; both ends included), `(min, max]` (min excluded) or `any` (every
    int). Numbers may use an exponent (1e5) and spaces between digit groups.
"""
import json
import math
import os
import re
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gr_check as T  # noqa: E402


def extra(p):
    p.add_argument("--params-tool", required=True)
    p.add_argument("--docs", required=True)


a = T.args(extra)

# The wrapped classes first: importing graupel after a proxy exists is the
# order py.import_order_* pins (py.wrapped_classes tests both orders).
import graupel  # noqa: E402
from paraview import servermanager  # noqa: E402
from paraview.simple import LoadPlugin  # noqa: E402

# The proxy of a core is named after it (rain_runoff -> RainRunoff, one name
# through every layer), a source or a filter; a core behind several proxies
# (sky: Lightning and CloudCover) names itself in each one's hint
# <GraupelCore name="sky"/>, and each of its rows is checked on every one of
# them that has the property (at least one must). CORES maps core -> list of
# (proxy group, proxy name, VTK class) and is filled from the plugin below,
# so a new core needs no line here.
CORES = {}
INT_MIN, INT_MAX = -2 ** 31, 2 ** 31 - 1

if not os.path.exists(a.params_tool):
    T.check(False, "graupel-params is not built (%s)" % a.params_tool)
    T.finish()
run = subprocess.run([a.params_tool], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
T.check(run.returncode == 0, "graupel-params exits 0 (%d: %s)" % (run.returncode, run.stderr))
tables = json.loads(run.stdout)
T.check(len(tables) >= 2, "graupel-params lists the cores: %s" % sorted(tables))


def same(x, y):
    return x == y or abs(x - y) <= 1e-12 * max(abs(x), abs(y))


def fmt(row):
    lo = "(%g" % row["min"] if row["min_open"] else "[%g" % row["min"]
    return "%s, %g] %s" % (lo, row["max"], row["unit"])


# ------------------------------------------------------------------ the XML
# A core lands before its filter (the VTK-free layer first); until the
# filter comes it is named here, so that a core without a proxy is a
# decision, not an oversight. Its table is checked against its page
# when the filter brings its page in docs/.
CORE_ONLY = set()
LoadPlugin(a.plugin, ns=globals())
pxm = servermanager.ProxyManager()
DECLARED = {}  # core -> [(group, name, class)] from <GraupelCore name=.../> hints
for group in ("sources", "filters"):
    it = pxm.GetProxyDefinitionManager().NewSingleGroupIterator(group)
    it.GoToFirstItem()
    while not it.IsDoneWithTraversal():
        proto = pxm.GetPrototypeProxy(group, it.GetProxyName())
        hints = proto.GetHints() if proto else None
        declared = hints.FindNestedElementByName("GraupelCore") if hints else None
        if declared is not None:
            DECLARED.setdefault(declared.GetAttribute("name"), []).append(
                (group, it.GetProxyName(), proto.GetVTKClassName()))
        it.GoToNextItem()
for core in tables:
    name = "".join(w.capitalize() for w in core.split("_"))
    for group in ("sources", "filters"):
        proto = pxm.GetPrototypeProxy(group, name)
        if proto is not None:
            CORES[core] = [(group, name, proto.GetVTKClassName())]
            break
    if core not in CORES and core in DECLARED:
        CORES[core] = DECLARED[core]
        name = " or ".join(n for _, n, _ in DECLARED[core])
    if core in CORE_ONLY:
        T.check(core not in CORES, "the core %s has its proxy %s now: take it off CORE_ONLY"
                % (core, name))
        continue
    T.check(core in CORES, "the core %s has a proxy named %s in the plugin" % (core, name))


# A property of several values (DensityRange) stands for several rows: its
# hint <GraupelTableRows rows="MinDensity MaxDensity"/> names the row of each
# value. ELEMENT maps (core, row) -> (property, value index); the docs row
# is the property's, its default cell the values in order.
ELEMENT = {}
for core, (group, name, _) in ((c, x) for c, xs in CORES.items() for x in xs):
    proto = pxm.GetPrototypeProxy(group, name)
    it = proto.NewPropertyIterator()
    it.Begin()
    while not it.IsAtEnd():
        hints = it.GetProperty().GetHints()
        rows = hints.FindNestedElementByName("GraupelTableRows") if hints else None
        if rows is not None:
            for k, r in enumerate(rows.GetAttribute("rows").split()):
                ELEMENT[(core, r)] = (it.GetKey(), k)
        it.Next()


def proxies_with(core, row):
    """The core's proxies that have the row's property (or its element)."""
    p = ELEMENT.get((core, row["property"]), (row["property"], 0))[0]
    have = [x for x in CORES[core] if pxm.GetPrototypeProxy(x[0], x[1]).GetProperty(p) is not None]
    return have if len(CORES[core]) > 1 else CORES[core]


def check_xml(core, row, proxy):
    group, name, _ = proxy
    proto = pxm.GetPrototypeProxy(group, name)
    p, index = ELEMENT.get((core, row["property"]), (row["property"], 0))
    prop = proto.GetProperty(p) if proto else None
    T.check(prop is not None, "%s has the property %s" % (name, p))
    if prop is None:
        return
    where = "%s.%s[%d] (table %s %s)" % (name, p, index, row["property"], fmt(row))
    # A prototype proxy is never modified: its values are the XML defaults.
    default = prop.GetElement(index)
    T.check(same(default, row["default"]),
            "%s: XML default %r, table %r" % (where, default, row["default"]))
    enum = prop.GetDomain("enum")
    boolean = prop.GetDomain("bool")
    rng = prop.GetDomain("range")
    if enum is not None:
        values = sorted(enum.GetEntryValue(i) for i in range(enum.GetNumberOfEntries()))
        want = list(range(int(row["min"]), int(row["max"]) + 1))
        T.check(row["integer"] and values == want,
                "%s: enumeration values %r, table %r" % (where, values, want))
        return
    if boolean is not None:
        T.check(row["integer"] and (row["min"], row["max"]) == (0, 1),
                "%s: a boolean, the table's range is not 0-1" % where)
        return
    T.check(rng is not None, "%s has a range domain" % where)
    if rng is None:
        return
    lo = rng.GetMinimum(0) if rng.GetMinimumExists(0) else None
    hi = rng.GetMaximum(0) if rng.GetMaximumExists(0) else None
    if lo is None and hi is None:
        # Unbounded: only a table spanning the whole type says the same.
        T.check(row["integer"] and row["min"] <= INT_MIN and row["max"] >= INT_MAX,
                "%s: the domain has no bounds" % where)
        return
    T.check(lo is not None and hi is not None, "%s: the domain has both ends (%r, %r)" % (where, lo, hi))
    if lo is None or hi is None:
        return
    hints = prop.GetHints()
    declared = hints.FindNestedElementByName("GraupelRange") if hints else None
    if declared is not None:
        dlo, dhi = float(declared.GetAttribute("min")), float(declared.GetAttribute("max"))
        T.check(same(dlo, row["min"]) and same(dhi, row["max"]),
                "%s: GraupelRange hint %g..%g" % (where, dlo, dhi))
        T.check(hi <= row["max"] and (lo > row["min"] if row["min_open"] else lo >= row["min"])
                and lo < hi, "%s: slider %g..%g lies inside the range" % (where, lo, hi))
        T.check(lo <= row["default"] <= hi, "%s: the default lies on the slider %g..%g" % (where, lo, hi))
    else:
        T.check(same(hi, row["max"]), "%s: domain max %g" % (where, hi))
        if row["min_open"]:
            T.check(lo > row["min"], "%s: domain min %g must exclude the open end" % (where, lo))
        else:
            T.check(same(lo, row["min"]), "%s: domain min %g" % (where, lo))


# ---------------------------------------------------------- the VTK classes
def check_class(core, row, proxy):
    cls = getattr(graupel, proxy[2])
    obj = cls()
    p = row["property"]
    get, set_ = getattr(obj, "Get" + p), getattr(obj, "Set" + p)
    where = "%s.Set%s (table %s)" % (proxy[2], p, fmt(row))
    T.check(same(float(get()), row["default"]), "%s: class default %r" % (where, get()))
    if isinstance(get(), bool) or (row["min"] <= INT_MIN and row["max"] >= INT_MAX):
        return  # a bool or a whole int: no value lies outside
    step = 1 if row["integer"] else max(abs(row["max"]), 1.0) * 1e-6
    if not (row["integer"] and row["max"] >= INT_MAX):  # an int setter takes nothing above
        set_(row["max"] + step)
        T.check(same(float(get()), row["max"]), "%s: max + %g reads back %r" % (where, step, get()))
    step = 1 if row["integer"] else max(abs(row["min"]), 1.0) * 1e-6
    set_(row["min"] - step)
    if row["min_open"]:
        T.check(float(get()) <= row["min"], "%s: below the open min reads back %r, inside the range"
                % (where, get()))
    else:
        T.check(same(float(get()), row["min"]), "%s: min - %g reads back %r" % (where, step, get()))


# --------------------------------------------------------------- the docs pages
NUM = r"-?[0-9][0-9  ]*(?:\.[0-9]+)?(?:e[+-]?[0-9]+)?"


def number(text):
    return float(re.sub(r"[  ]", "", text))


def doc_rows(folder):
    """(proxy, property) -> list of (default cell, unit-range cell) of the table
    rows of the pages in docs/, each under its heading "# Label (`Proxy`,
    `vtkClass`)" (two filters may both have a `Seed`)."""
    rows = {}
    for page in sorted(os.listdir(folder)):
        if page.endswith(".md"):
            doc_page_rows(os.path.join(folder, page), rows)
    return rows


def doc_page_rows(path, rows):
    proxy = None
    with open(path, encoding="utf-8") as f:
        for line in f:
            heading = re.match(r"#+ .*\(`([A-Za-z]+)`", line)
            if heading:
                proxy = heading.group(1)
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            if len(cells) >= 3 and re.fullmatch(r"`[A-Za-z]+`", cells[0]):
                rows.setdefault((proxy, cells[0].strip("`")), []).append((cells[1], cells[2]))
    return rows


def parse_range(cell):
    """'mm/h, 0–3600' -> ('mm/h', 0, 3600, open); 'any' -> ('', None, None, False)."""
    m = re.fullmatch(r"(?:(.*?),\s*)?(any|\((%s),\s*(%s)\]|(%s)\s*–\s*(%s))" % (NUM, NUM, NUM, NUM),
                     cell)
    if not m:
        return None
    unit = m.group(1) or ""
    if m.group(2) == "any":
        return unit, None, None, False
    if m.group(3) is not None:
        return unit, number(m.group(3)), number(m.group(4)), True
    return unit, number(m.group(5)), number(m.group(6)), False


readme = doc_rows(a.docs)


def check_readme(core, row, proxy):
    p, index = ELEMENT.get((core, row["property"]), (row["property"], -1))
    found = readme.get((proxy[1], p), [])
    T.check(len(found) == 1, "docs: one table row for `%s` on the page of %s (found %d)"
            % (p, proxy[1], len(found)))
    if len(found) != 1:
        return
    default_cell, range_cell = found[0]
    nums = re.findall(NUM, default_cell)
    T.check(len(nums) > max(index, 0) and same(number(nums[index]), row["default"]),
            "docs `%s`: default '%s', table %r" % (p, default_cell, row["default"]))
    r = parse_range(range_cell)
    T.check(r is not None, "docs `%s`: '%s' is not 'unit, min–max', 'unit, (min, max]' or 'any'"
            % (p, range_cell))
    if r is None:
        return
    unit, lo, hi, open_ = r
    T.check(unit == row["unit"], "docs `%s`: unit '%s', table '%s'" % (p, unit, row["unit"]))
    if lo is None:
        T.check(row["integer"] and row["min"] <= INT_MIN and row["max"] >= INT_MAX,
                "docs `%s`: 'any', but the table has %s" % (p, fmt(row)))
    else:
        T.check(same(lo, row["min"]) and same(hi, row["max"]) and open_ == bool(row["min_open"]),
                "docs `%s`: '%s', table %s" % (p, range_cell, fmt(row)))


for core, rows in sorted(tables.items()):
    if core not in CORES:
        continue
    T.check(len(rows) > 0, "%s has a parameter table" % core)
    for row in rows:
        T.check(all(isinstance(row.get(k), (int, float)) and math.isfinite(row[k])
                    for k in ("min", "max", "default", "to_core")),
                "%s.%s: finite numbers" % (core, row.get("property")))
        T.check(row["min"] <= row["default"] <= row["max"] and
                not (row["min_open"] and row["default"] == row["min"]),
                "%s.%s: the default %g lies in %s" % (core, row["property"], row["default"], fmt(row)))
        proxies = proxies_with(core, row)
        T.check(len(proxies) > 0, "%s.%s: a proxy of the core has the property"
                % (core, row["property"]))
        for proxy in proxies:
            check_xml(core, row, proxy)
            check_class(core, row, proxy)
            check_readme(core, row, proxy)

# ------------------------------------------------- every proxy has its page
# Every proxy the plugin adds (its VTK class is one of graupel's) has its
# page docs/<Proxy>.md under a heading "# Label (`Proxy`, `vtkClass`)", and
# every property the panel can show (all but Input) is named there in
# backticks, or, for what every simulation shares, in docs/Simulations.md.
shared = open(os.path.join(a.docs, "Simulations.md"), encoding="utf-8").read()
pages = 0
for group in ("sources", "filters", "writers"):
    it = pxm.GetProxyDefinitionManager().NewSingleGroupIterator(group)
    it.GoToFirstItem()
    while not it.IsDoneWithTraversal():
        name = it.GetProxyName()
        proto = pxm.GetPrototypeProxy(group, name)
        it.GoToNextItem()
        if proto is None or not hasattr(graupel, proto.GetVTKClassName() or ""):
            continue
        pages += 1
        path = os.path.join(a.docs, name + ".md")
        page = open(path, encoding="utf-8").read() if os.path.exists(path) else ""
        T.check(re.search(r"^# .*\(`%s`, `%s`\)" % (name, proto.GetVTKClassName()), page, re.M)
                is not None, "docs/%s.md exists with its heading" % name)
        props = proto.NewPropertyIterator()
        props.Begin()
        while not props.IsAtEnd():
            key, prop = props.GetKey(), props.GetProperty()
            props.Next()
            if key == "Input" or prop.GetInformationOnly() or prop.GetPanelVisibility() == "never":
                continue
            T.check("`%s`" % key in page or "`%s`" % key in shared,
                    "docs/%s.md names the property `%s`" % (name, key))
T.check(pages >= 14, "%d Graupel proxies have pages" % pages)

T.finish()
