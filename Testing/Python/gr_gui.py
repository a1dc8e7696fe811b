"""What the GUI tests share: a QtTesting script written from a list of
(object, command, arguments) events, the `paraview` client run on it with the
plugin on PV_PLUGIN_PATH, and the state file it saved read back.
(QtTesting's Python scripts cannot be used: their thread waits forever for
the Python lock the GUI holds.)"""
import os
import subprocess
import sys
import xml.etree.ElementTree as ET

APPLY = "pqClientMainWindow/propertiesDock/propertiesPanel/Accept"
PANEL = ("pqClientMainWindow/propertiesDock/propertiesPanel/scrollArea/qt_scrollarea_viewport/"
         "scrollAreaWidgetContents/PropertiesFrame/ProxyPanel/")


def setup(name):
    """The test's arguments and files: (scratch, plugin_dir, state, script),
    the state NAME.pvsm (removed if an earlier run left one) and the script
    NAME.xml in the scratch folder."""
    scratch = sys.argv[sys.argv.index("--scratch") + 1]
    plugin_dir = sys.argv[sys.argv.index("--plugin-dir") + 1]
    state = os.path.join(scratch, name + ".pvsm")
    if os.path.exists(state):
        os.remove(state)
    return scratch, plugin_dir, state, os.path.join(scratch, name + ".xml")


def write_events(path, events):
    with open(path, "w") as f:
        f.write('<?xml version="1.0" ?>\n<pqevents>\n')
        for obj, command, arguments in events:
            f.write('  <pqevent object="%s" command="%s" arguments="%s"/>\n'
                    % (obj, command, arguments))
        f.write("</pqevents>\n")


def paraview(script, plugin_dir, exit=True, **popen):
    """The GUI playing script: run to its end (exit, a CompletedProcess) or
    left running (a Popen)."""
    env = dict(os.environ, PV_PLUGIN_PATH=plugin_dir)
    cmd = ["paraview", "--dr", "--test-script=" + script] + (["--exit"] if exit else [])
    if exit:
        return subprocess.run(cmd, env=env, timeout=240, **popen)
    return subprocess.Popen(cmd, env=env, **popen)


def play_to_state(script, plugin_dir, state, **popen):
    """Plays script in the GUI to its end and reads the state it saved;
    exits the test (status 1) when it saved none. Returns (the finished
    process, the State)."""
    proc = paraview(script, plugin_dir, **popen)
    if isinstance(proc.stdout, str):
        print(proc.stdout[-4000:])
    print("paraview exit code %d" % proc.returncode)
    if not os.path.exists(state):
        print("no state saved: the GUI script did not get through")
        sys.exit(1)
    return proc, State(state)


class State:
    """A saved state: its pipeline sources' names and every proxy by id."""

    def __init__(self, path):
        root = ET.parse(path).getroot().find("ServerManagerState")
        self.names = {i.get("id"): i.get("name") for c in root.findall("ProxyCollection")
                      if c.get("name") == "sources" for i in c.findall("Item")}
        self.proxies = {p.get("id"): p for p in root.findall("Proxy")}

    @staticmethod
    def prop(proxy, name):
        """(element values, [(proxy id, output port)]) of a property."""
        for q in proxy.findall("Property"):
            if q.get("name") == name:
                return ([e.get("value") for e in q.findall("Element")],
                        [(d.get("value"), d.get("output_port")) for d in q.findall("Proxy")])
        return [], []

    def by_type(self, xml_name):
        """The ids of the pipeline sources of a proxy type."""
        return [i for i, p in self.proxies.items() if p.get("type") == xml_name and i in self.names]

    def bar_for(self, repr_proxy):
        """The scalar bar of a representation's lookup table."""
        lut = self.prop(repr_proxy, "LookupTable")[1]
        for p in self.proxies.values():
            if (p.get("type") == "ScalarBarWidgetRepresentation"
                    and self.prop(p, "LookupTable")[1] == lut):
                return p
        return None
