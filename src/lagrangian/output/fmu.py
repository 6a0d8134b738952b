"""An FMI 2.0 FMU of a model, Model Exchange and Co-Simulation (classical Runge-Kutta, internal
steps of at most 1 ms): the standalone C of its dynamics (System.to_c) under an FMI wrapper of
our own, compiled for this platform, zipped with its modelDescription.xml.

Variables (SI): the states q and q_dot (outputs, continuous, exact start values), their
derivatives der(q) = q_dot and der(q_dot) = M^-1 (tau - b), the model's parameters (tunable)
and one generalized force Q_<coordinate> per coordinate (an input, N m or N, 0 by default,
on top of the model's own loads).
No text a user wrote reaches the C: the wrapper names only our own identifiers and numbers; the
model's name and variable names appear in the XML only, escaped by ElementTree.
"""

from __future__ import annotations

import hashlib
import io
import re
import uuid
import xml.etree.ElementTree as ElementTree
import zipfile
from collections.abc import Sequence
from pathlib import Path

from ..compile.shared_library import library_suffix, platform_folder, shared_library
from ..dynamics.standalone.standalone import StandaloneSource
from ..errors import InputError
from .files import atomic_write, check_generated_target

PREFIX = "lg_fmu_model"  # the standalone C's prefix: ours, whatever the model is called


def model_identifier(path: Path) -> str:
    """The FMU's modelIdentifier (its binary's name) from the file name: a C identifier."""
    text = re.sub(r"[^A-Za-z0-9_]", "_", path.stem)[:60] or "model"
    return text if text[0].isalpha() else "m_" + text


def fmu_bytes(code: StandaloneSource, identifier: str, *, name: str, description: str,
              coordinates: Sequence[str], units: Sequence[str | None],
              parameters: Sequence[tuple[str, float, str | None]],
              initial: Sequence[float]) -> bytes:
    """The FMU archive: modelDescription.xml, binaries/<platform>/<identifier>.<so>, sources/."""
    n = len(coordinates)
    wrapper = _wrapper(n, len(parameters), initial)
    sources = {f"{PREFIX}.h": code.header, f"{PREFIX}.c": code.source, "fmi2_model.c": wrapper}
    library = shared_library(sources, identifier + library_suffix())
    xml = _model_description(identifier, name, description, coordinates, units, parameters,
                             initial, sources)
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", zipfile.ZIP_DEFLATED) as archive:
        archive.writestr("modelDescription.xml", xml)
        archive.writestr(f"binaries/{platform_folder()}/{identifier}{library_suffix()}", library)
        for file_name, text in sources.items():
            archive.writestr(f"sources/{file_name}", text)
    return buffer.getvalue()


def write_fmu(data: bytes, path: str | Path) -> Path:
    """Write the FMU archive atomically; a file in the way that we did not write is refused."""
    path = Path(path)
    if path.suffix.lower() != ".fmu":
        raise InputError(f"{path} does not end in .fmu", field="fmu")
    check_generated_target(path)
    return atomic_write(path, data)


def input_name(coordinate: str, taken) -> str:
    """The input of the generalized force on ``coordinate``: Q_<coordinate>, made unique."""
    name = f"Q_{coordinate}"
    while name in taken:
        name += "_input"
    return name


def _variable(parent, name: str, reference: int, causality: str, variability: str,
              description: str = "", initial: str | None = None, **real) -> None:
    attributes = {"name": name, "valueReference": str(reference), "causality": causality,
                  "variability": variability}
    if description:
        attributes["description"] = description
    if initial:
        attributes["initial"] = initial
    variable = ElementTree.SubElement(parent, "ScalarVariable", attributes)
    ElementTree.SubElement(variable, "Real", {k: v for k, v in real.items() if v is not None})


def _model_description(identifier, name, description, coordinates, units, parameters, initial,
                       sources) -> str:
    n, count = len(coordinates), len(parameters)
    digest = hashlib.sha256(repr((identifier, name, coordinates, parameters, initial,
                                  sorted(sources.items()))).encode()).hexdigest()
    root = ElementTree.Element("fmiModelDescription", {
        "fmiVersion": "2.0", "modelName": name or identifier,
        "guid": "{" + str(uuid.UUID(digest[:32])) + "}",
        "description": description[:500], "generationTool": "lagrangian",
        "variableNamingConvention": "structured", "numberOfEventIndicators": "0"})
    me = ElementTree.SubElement(root, "ModelExchange", {
        "modelIdentifier": identifier, "canNotUseMemoryManagementFunctions": "true",
        "canGetAndSetFMUstate": "false", "canSerializeFMUstate": "false"})
    cs = ElementTree.SubElement(root, "CoSimulation", {
        "modelIdentifier": identifier, "canHandleVariableCommunicationStepSize": "true",
        "canNotUseMemoryManagementFunctions": "true", "canGetAndSetFMUstate": "false",
        "canSerializeFMUstate": "false"})
    for interface in (me, cs):
        files = ElementTree.SubElement(interface, "SourceFiles")
        for file_name in sources:
            if file_name.endswith(".c"):
                ElementTree.SubElement(files, "File", {"name": file_name})
    ElementTree.SubElement(root, "DefaultExperiment", {"startTime": "0.0", "stopTime": "10.0",
                                                        "tolerance": "1e-09"})
    variables = ElementTree.SubElement(root, "ModelVariables")
    # units in the descriptions: FMI units need <UnitDefinitions> in SI base exponents
    for i, (c, u) in enumerate(zip(coordinates, units, strict=True)):
        _variable(variables, c, i, "output", "continuous", f"coordinate {c} ({u or 'SI'})",
                  "exact", start=repr(float(initial[i])))
    for i, (c, u) in enumerate(zip(coordinates, units, strict=True)):
        _variable(variables, f"{c}_dot", n + i, "output", "continuous",
                  f"rate of {c} ({u + '/s' if u else 'SI'})", "exact",
                  start=repr(float(initial[n + i])))
    for i, c in enumerate(coordinates):
        _variable(variables, f"der({c})", 2 * n + i, "local", "continuous", "",
                  "calculated", derivative=str(i + 1))
    for i, c in enumerate(coordinates):
        _variable(variables, f"der({c}_dot)", 3 * n + i, "local", "continuous", "",
                  "calculated", derivative=str(n + i + 1))
    for k, (p, value, unit) in enumerate(parameters):
        _variable(variables, p, 4 * n + k, "parameter", "tunable",
                  f"parameter {p} ({unit or 'SI'})", "exact", start=repr(float(value)))
    taken = {*coordinates, *(f"{c}_dot" for c in coordinates), *(p for p, *_ in parameters)}
    for i, c in enumerate(coordinates):
        _variable(variables, input_name(c, taken), 4 * n + count + i, "input", "continuous",
                  f"generalized force on {c}", start="0.0")
    structure = ElementTree.SubElement(root, "ModelStructure")
    outputs = ElementTree.SubElement(structure, "Outputs")
    for i in range(2 * n):
        ElementTree.SubElement(outputs, "Unknown", {"index": str(i + 1)})
    derivatives = ElementTree.SubElement(structure, "Derivatives")
    for i in range(2 * n):
        ElementTree.SubElement(derivatives, "Unknown", {"index": str(2 * n + i + 1)})
    unknowns = ElementTree.SubElement(structure, "InitialUnknowns")
    for i in range(2 * n):
        ElementTree.SubElement(unknowns, "Unknown", {"index": str(2 * n + i + 1)})
    ElementTree.indent(root)
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ElementTree.tostring(
        root, encoding="unicode") + "\n"


def _wrapper(n: int, count: int, initial: Sequence[float]) -> str:
    """The FMI 2.0 Model Exchange functions over the standalone C: numbers and our names only."""
    start = ", ".join(repr(float(x)) for x in initial)
    return (_WRAPPER.replace("@N@", str(n)).replace("@NP@", str(count))
            .replace("@X0@", start).replace("@P@", PREFIX))


_WRAPPER = r"""/* FMI 2.0 Model Exchange wrapper, generated by lagrangian. */
#include <stdlib.h>
#include <string.h>
#include "@P@.h"

#define N @N@
#define NP @NP@
#define NX (2 * N)

typedef void *fmi2Component;
typedef void *fmi2ComponentEnvironment;
typedef void *fmi2FMUstate;
typedef unsigned int fmi2ValueReference;
typedef double fmi2Real;
typedef int fmi2Integer;
typedef int fmi2Boolean;
typedef char fmi2Char;
typedef const fmi2Char *fmi2String;
typedef char fmi2Byte;
typedef enum { fmi2OK, fmi2Warning, fmi2Discard, fmi2Error, fmi2Fatal, fmi2Pending } fmi2Status;
typedef enum { fmi2ModelExchange, fmi2CoSimulation } fmi2Type;
typedef enum { fmi2DoStepStatus, fmi2PendingStatus, fmi2LastSuccessfulTime, fmi2Terminated }
    fmi2StatusKind;
typedef void (*fmi2CallbackLogger)(fmi2ComponentEnvironment, fmi2String, fmi2Status, fmi2String,
                                   fmi2String, ...);
typedef struct {
    fmi2CallbackLogger logger;
    void *(*allocateMemory)(size_t, size_t);
    void (*freeMemory)(void *);
    void (*stepFinished)(fmi2ComponentEnvironment, fmi2Status);
    fmi2ComponentEnvironment componentEnvironment;
} fmi2CallbackFunctions;
typedef struct {
    fmi2Boolean newDiscreteStatesNeeded;
    fmi2Boolean terminateSimulation;
    fmi2Boolean nominalsOfContinuousStatesChanged;
    fmi2Boolean valuesOfContinuousStatesChanged;
    fmi2Boolean nextEventTimeDefined;
    fmi2Real nextEventTime;
} fmi2EventInfo;

#define EXPORT __attribute__((visibility("default")))

typedef struct {
    double x[NX + 1], p[NP + 1], tau[N + 1], a[N + 1], t;
    int fresh;
} Model;

static const double initial_state[NX] = {@X0@};

static void reset(Model *m) {
    memset(m, 0, sizeof(*m));
    memcpy(m->x, initial_state, sizeof(initial_state));
    for (int k = 0; k < NP; k++) m->p[k] = @P@_parameters[k];
}

static int accelerations(Model *m) {
    if (m->fresh) return 0;
    if (@P@_forward_dynamics(m->x, m->x + N, m->tau, m->p, m->a) != 0) return -1;
    m->fresh = 1;
    return 0;
}

EXPORT const char *fmi2GetTypesPlatform(void) { return "default"; }
EXPORT const char *fmi2GetVersion(void) { return "2.0"; }
EXPORT fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean on, size_t n,
                                      const fmi2String cats[]) {
    (void)c; (void)on; (void)n; (void)cats; return fmi2OK;
}
EXPORT fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid,
                                     fmi2String location, const fmi2CallbackFunctions *f,
                                     fmi2Boolean visible, fmi2Boolean logging) {
    (void)name; (void)guid; (void)location; (void)f; (void)visible; (void)logging;
    if (type != fmi2ModelExchange && type != fmi2CoSimulation) return NULL;
    Model *m = (Model *)calloc(1, sizeof(Model));
    if (m) reset(m);
    return m;
}
EXPORT void fmi2FreeInstance(fmi2Component c) { free(c); }
EXPORT fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean tol, fmi2Real tolerance,
                                      fmi2Real start, fmi2Boolean stopDefined, fmi2Real stop) {
    (void)tol; (void)tolerance; (void)stopDefined; (void)stop;
    ((Model *)c)->t = start; return fmi2OK;
}
EXPORT fmi2Status fmi2EnterInitializationMode(fmi2Component c) { (void)c; return fmi2OK; }
EXPORT fmi2Status fmi2ExitInitializationMode(fmi2Component c) { (void)c; return fmi2OK; }
EXPORT fmi2Status fmi2Terminate(fmi2Component c) { (void)c; return fmi2OK; }
EXPORT fmi2Status fmi2Reset(fmi2Component c) { reset((Model *)c); return fmi2OK; }

EXPORT fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                              fmi2Real value[]) {
    Model *m = (Model *)c;
    for (size_t i = 0; i < nvr; i++) {
        unsigned int r = vr[i];
        if (r < (unsigned)NX) value[i] = m->x[r];
        else if (r < (unsigned)(3 * N)) value[i] = m->x[r - N];
        else if (r < (unsigned)(4 * N)) {
            if (accelerations(m) != 0) return fmi2Error;
            value[i] = m->a[r - 3 * N];
        } else if (r < (unsigned)(4 * N + NP)) value[i] = m->p[r - 4 * N];
        else if (r < (unsigned)(5 * N + NP)) value[i] = m->tau[r - 4 * N - NP];
        else return fmi2Error;
    }
    return fmi2OK;
}
EXPORT fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                              const fmi2Real value[]) {
    Model *m = (Model *)c;
    m->fresh = 0;
    for (size_t i = 0; i < nvr; i++) {
        unsigned int r = vr[i];
        if (r < (unsigned)NX) m->x[r] = value[i];
        else if (r < (unsigned)(4 * N)) return fmi2Error;
        else if (r < (unsigned)(4 * N + NP)) m->p[r - 4 * N] = value[i];
        else if (r < (unsigned)(5 * N + NP)) m->tau[r - 4 * N - NP] = value[i];
        else return fmi2Error;
    }
    return fmi2OK;
}
EXPORT fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                 fmi2Integer v[]) {
    (void)c; (void)vr; (void)v; return n ? fmi2Error : fmi2OK;
}
EXPORT fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                 fmi2Boolean v[]) {
    (void)c; (void)vr; (void)v; return n ? fmi2Error : fmi2OK;
}
EXPORT fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                fmi2String v[]) {
    (void)c; (void)vr; (void)v; return n ? fmi2Error : fmi2OK;
}
EXPORT fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                 const fmi2Integer v[]) {
    (void)c; (void)vr; (void)v; return n ? fmi2Error : fmi2OK;
}
EXPORT fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                 const fmi2Boolean v[]) {
    (void)c; (void)vr; (void)v; return n ? fmi2Error : fmi2OK;
}
EXPORT fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                const fmi2String v[]) {
    (void)c; (void)vr; (void)v; return n ? fmi2Error : fmi2OK;
}
EXPORT fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *s) {
    (void)c; (void)s; return fmi2Error;
}
EXPORT fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate s) {
    (void)c; (void)s; return fmi2Error;
}
EXPORT fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *s) {
    (void)c; (void)s; return fmi2Error;
}
EXPORT fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate s, size_t *n) {
    (void)c; (void)s; (void)n; return fmi2Error;
}
EXPORT fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate s, fmi2Byte b[],
                                        size_t n) {
    (void)c; (void)s; (void)b; (void)n; return fmi2Error;
}
EXPORT fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte b[], size_t n,
                                          fmi2FMUstate *s) {
    (void)c; (void)b; (void)n; (void)s; return fmi2Error;
}
EXPORT fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference u[],
                                               size_t nu, const fmi2ValueReference z[],
                                               size_t nz, const fmi2Real dv[], fmi2Real dz[]) {
    (void)c; (void)u; (void)nu; (void)z; (void)nz; (void)dv; (void)dz; return fmi2Error;
}

EXPORT fmi2Status fmi2EnterEventMode(fmi2Component c) { (void)c; return fmi2OK; }
EXPORT fmi2Status fmi2NewDiscreteStates(fmi2Component c, fmi2EventInfo *info) {
    (void)c;
    info->newDiscreteStatesNeeded = 0;
    info->terminateSimulation = 0;
    info->nominalsOfContinuousStatesChanged = 0;
    info->valuesOfContinuousStatesChanged = 0;
    info->nextEventTimeDefined = 0;
    info->nextEventTime = 0.0;
    return fmi2OK;
}
EXPORT fmi2Status fmi2EnterContinuousTimeMode(fmi2Component c) { (void)c; return fmi2OK; }
EXPORT fmi2Status fmi2CompletedIntegratorStep(fmi2Component c, fmi2Boolean noSet,
                                              fmi2Boolean *enter, fmi2Boolean *stop) {
    (void)c; (void)noSet; *enter = 0; *stop = 0; return fmi2OK;
}
EXPORT fmi2Status fmi2SetTime(fmi2Component c, fmi2Real t) {
    ((Model *)c)->t = t; return fmi2OK;
}
EXPORT fmi2Status fmi2SetContinuousStates(fmi2Component c, const fmi2Real x[], size_t nx) {
    Model *m = (Model *)c;
    if (nx != (size_t)NX) return fmi2Error;
    memcpy(m->x, x, sizeof(double) * NX);
    m->fresh = 0;
    return fmi2OK;
}
EXPORT fmi2Status fmi2GetDerivatives(fmi2Component c, fmi2Real dx[], size_t nx) {
    Model *m = (Model *)c;
    if (nx != (size_t)NX || accelerations(m) != 0) return fmi2Error;
    memcpy(dx, m->x + N, sizeof(double) * N);
    memcpy(dx + N, m->a, sizeof(double) * N);
    return fmi2OK;
}
EXPORT fmi2Status fmi2GetEventIndicators(fmi2Component c, fmi2Real z[], size_t nz) {
    (void)c; (void)z; return nz ? fmi2Error : fmi2OK;
}
EXPORT fmi2Status fmi2GetContinuousStates(fmi2Component c, fmi2Real x[], size_t nx) {
    Model *m = (Model *)c;
    if (nx != (size_t)NX) return fmi2Error;
    memcpy(x, m->x, sizeof(double) * NX);
    return fmi2OK;
}
/* Co-Simulation: classical Runge-Kutta, internal steps of at most CS_STEP s. */
#define CS_STEP 1e-3

static int derivative(Model *m, const double *x, double *dx) {
    double a[N + 1];
    if (@P@_forward_dynamics(x, x + N, m->tau, m->p, a) != 0) return -1;
    memcpy(dx, x + N, sizeof(double) * N);
    memcpy(dx + N, a, sizeof(double) * N);
    return 0;
}

EXPORT fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean noSet) {
    Model *m = (Model *)c;
    (void)noSet;
    if (!(h >= 0)) return fmi2Error;
    int steps = (int)(h / CS_STEP) + 1;
    double dt = h / steps, k1[NX], k2[NX], k3[NX], k4[NX], y[NX];
    for (int s = 0; s < steps; s++) {
        double *x = m->x;
        if (derivative(m, x, k1)) return fmi2Error;
        for (int i = 0; i < NX; i++) y[i] = x[i] + 0.5 * dt * k1[i];
        if (derivative(m, y, k2)) return fmi2Error;
        for (int i = 0; i < NX; i++) y[i] = x[i] + 0.5 * dt * k2[i];
        if (derivative(m, y, k3)) return fmi2Error;
        for (int i = 0; i < NX; i++) y[i] = x[i] + dt * k3[i];
        if (derivative(m, y, k4)) return fmi2Error;
        for (int i = 0; i < NX; i++) x[i] += dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
    }
    m->t = t + h;
    m->fresh = 0;
    return fmi2OK;
}
EXPORT fmi2Status fmi2CancelStep(fmi2Component c) { (void)c; return fmi2Error; }
EXPORT fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[],
                                              size_t n, const fmi2Integer order[],
                                              const fmi2Real v[]) {
    (void)c; (void)vr; (void)order; (void)v; return n ? fmi2Error : fmi2OK;
}
EXPORT fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[],
                                               size_t n, const fmi2Integer order[],
                                               fmi2Real v[]) {
    (void)c; (void)vr; (void)order; (void)v; return n ? fmi2Error : fmi2OK;
}
EXPORT fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *v) {
    (void)c; (void)s; (void)v; return fmi2Discard;
}
EXPORT fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *v) {
    Model *m = (Model *)c;
    if (s != fmi2LastSuccessfulTime) return fmi2Discard;
    *v = m->t; return fmi2OK;
}
EXPORT fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s,
                                       fmi2Integer *v) {
    (void)c; (void)s; (void)v; return fmi2Discard;
}
EXPORT fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s,
                                       fmi2Boolean *v) {
    (void)c; (void)s; (void)v; return fmi2Discard;
}
EXPORT fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *v) {
    (void)c; (void)s; (void)v; return fmi2Discard;
}

EXPORT fmi2Status fmi2GetNominalsOfContinuousStates(fmi2Component c, fmi2Real x[], size_t nx) {
    (void)c;
    for (size_t i = 0; i < nx; i++) x[i] = 1.0;
    return fmi2OK;
}
"""

__all__ = ["PREFIX", "fmu_bytes", "input_name", "model_identifier", "write_fmu"]
