// The HTML quality report (html_report.h). One file: the figures and the histogram are written
// here (inline SVG); the mesh goes in as JSON (points to 7 significant digits, hexes, per-hex
// scaled Jacobian to 4 decimals) for the viewer script below, plain WebGL 1 with no library:
// it finds each hex face's neighbour, keeps the hexes whose centroid lies below a plane moved by
// a slider, and draws the faces of that set that no kept hex shares, coloured by their hex's
// scaled Jacobian, with their edges; the worst hexes can be drawn whole on top. The page reports
// its state in #status ("viewer-ready: ...", or why not), which the tests read.
#include "hexpeel/html_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace hexpeel {
namespace {

std::string escape_html(const std::string& s) {
  std::string out;
  for (const char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

std::string fmt(const char* f, double x) {
  if (!std::isfinite(x)) return "n/a";
  char buf[64];
  std::snprintf(buf, sizeof(buf), f, x);
  return buf;
}

/// The RdYlGn-like ramp of the viewer, for the histogram's bars: s in [0, 1], below 0 dark red.
std::string ramp(double s) {
  static const double stops[5][4] = {{0.0, 0.84, 0.19, 0.15}, {0.3, 0.99, 0.68, 0.38},
                                     {0.6, 0.99, 1.0, 0.75},  {0.8, 0.65, 0.85, 0.42},
                                     {1.0, 0.10, 0.60, 0.31}};
  double rgb[3] = {0.45, 0.0, 0.0};
  if (s > 0.0) {
    s = std::min(s, 1.0);
    int i = 0;
    while (i < 3 && s > stops[i + 1][0]) ++i;
    const double t = (s - stops[i][0]) / (stops[i + 1][0] - stops[i][0]);
    for (int k = 0; k < 3; ++k) rgb[k] = stops[i][k + 1] + t * (stops[i + 1][k + 1] - stops[i][k + 1]);
  }
  char buf[16];
  std::snprintf(buf, sizeof(buf), "#%02x%02x%02x", static_cast<int>(std::lround(255 * rgb[0])),
                static_cast<int>(std::lround(255 * rgb[1])), static_cast<int>(std::lround(255 * rgb[2])));
  return buf;
}

std::string histogram_svg(const QualityReport& q) {
  const int bins = static_cast<int>(q.histogram.size());
  if (bins == 0) return "<p>No hexes.</p>";
  const int w = 560, h = 180, left = 40, bottom = 24;
  const int top = *std::max_element(q.histogram.begin(), q.histogram.end());
  std::string s = "<svg class=\"hist\" width=\"" + std::to_string(w) + "\" height=\"" +
                  std::to_string(h) + "\" role=\"img\" aria-label=\"scaled Jacobian histogram\">";
  const double bw = static_cast<double>(w - left - 10) / bins;
  for (int i = 0; i < bins; ++i) {
    const double lo = -1.0 + 2.0 * i / bins, hi = -1.0 + 2.0 * (i + 1) / bins;
    const double bh = top > 0 ? (h - bottom - 10) * static_cast<double>(q.histogram[i]) / top : 0.0;
    s += "<rect x=\"" + fmt("%.1f", left + i * bw) + "\" y=\"" + fmt("%.1f", h - bottom - bh) +
         "\" width=\"" + fmt("%.1f", bw - 1) + "\" height=\"" + fmt("%.1f", bh) + "\" fill=\"" +
         ramp(0.5 * (lo + hi)) + "\"><title>[" + fmt("%.2f", lo) + ", " + fmt("%.2f", hi) + "): " +
         std::to_string(q.histogram[i]) + " hexes</title></rect>";
  }
  for (const double x : {-1.0, -0.5, 0.0, 0.5, 1.0}) {
    const double px = left + (x + 1.0) / 2.0 * (w - left - 10);
    s += "<text x=\"" + fmt("%.1f", px) + "\" y=\"" + std::to_string(h - 6) +
         "\" text-anchor=\"middle\">" + fmt("%g", x) + "</text>";
  }
  s += "<text x=\"4\" y=\"14\">" + std::to_string(top) + "</text></svg>";
  return s;
}

constexpr const char* kStyle = R"CSS(
body{font:14px/1.4 system-ui,sans-serif;margin:16px;color:#222;max-width:1100px}
h1{font-size:20px;margin:0 0 8px}
table{border-collapse:collapse;margin:6px 0}
td,th{padding:2px 10px;border-bottom:1px solid #ddd;text-align:right}
th{text-align:left;font-weight:600}
.hist text{font-size:11px;fill:#444}
#view{border:1px solid #bbb;width:800px;height:560px;cursor:grab;display:block}
#controls{margin:6px 0}
#status{font-size:12px;color:#555}
#status.error{color:#b00}
.legend span{display:inline-block;width:60px;height:10px}
)CSS";

constexpr const char* kScript = R"JS(
(function () {
  'use strict';
  var status = document.getElementById('status');
  function say(text, error) { status.textContent = text; status.className = error ? 'error' : ''; }
  window.addEventListener('error', function (e) { say('viewer-error: ' + e.message, true); });
  var D = JSON.parse(document.getElementById('mesh-data').textContent);
  if (!D.view) { say('viewer-off: ' + D.note); return; }
  var canvas = document.getElementById('view');
  var gl = canvas.getContext('webgl', { antialias: true, preserveDrawingBuffer: true });
  if (!gl) { say('viewer-unavailable: this browser gives no WebGL context'); return; }
  var P = D.points, H = D.hexes, S = D.sj, nh = S.length;
  var FACES = [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]];
  // Neighbour of every hex face (-1 on the boundary), by the face's sorted corner ids.
  var nb = new Int32Array(6 * nh).fill(-1), seen = new Map();
  for (var h = 0; h < nh; h++) {
    for (var f = 0; f < 6; f++) {
      var k = FACES[f].map(function (i) { return H[8 * h + i]; }).sort(function (a, b) { return a - b; }).join(',');
      var o = seen.get(k);
      if (o === undefined) seen.set(k, 6 * h + f); else { nb[6 * h + f] = (o / 6) | 0; nb[o] = h; }
    }
  }
  seen = null;
  var C = new Float32Array(3 * nh), lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
  for (var v = 0; v < P.length / 3; v++)
    for (var a = 0; a < 3; a++) { lo[a] = Math.min(lo[a], P[3 * v + a]); hi[a] = Math.max(hi[a], P[3 * v + a]); }
  for (h = 0; h < nh; h++)
    for (a = 0; a < 3; a++) {
      var s = 0; for (var c = 0; c < 8; c++) s += P[3 * H[8 * h + c] + a];
      C[3 * h + a] = s / 8;
    }
  var centre = [0, 1, 2].map(function (i) { return (lo[i] + hi[i]) / 2; });
  var radius = Math.max(1e-30, 0.5 * Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]));
  var STOPS = [[0, .84, .19, .15], [.3, .99, .68, .38], [.6, .99, 1, .75], [.8, .65, .85, .42], [1, .1, .6, .31]];
  function ramp(x) {
    if (!(x > 0)) return [.45, 0, 0];
    x = Math.min(x, 1);
    var i = 0; while (i < 3 && x > STOPS[i + 1][0]) i++;
    var t = (x - STOPS[i][0]) / (STOPS[i + 1][0] - STOPS[i][0]);
    return [1, 2, 3].map(function (j) { return STOPS[i][j] + t * (STOPS[i + 1][j] - STOPS[i][j]); });
  }
  function shader(type, src) {
    var sh = gl.createShader(type); gl.shaderSource(sh, src); gl.compileShader(sh);
    if (!gl.getShaderParameter(sh, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(sh));
    return sh;
  }
  var prog = gl.createProgram();
  gl.attachShader(prog, shader(gl.VERTEX_SHADER,
    'attribute vec3 p; attribute vec3 n; attribute vec3 c; uniform mat4 m; uniform mat3 r;' +
    'uniform float lit; varying vec3 vc; void main() { vec3 q = normalize(r * n);' +
    'vc = lit > 0.5 ? c * (0.35 + 0.65 * abs(q.z)) : c; gl_Position = m * vec4(p, 1.0); }'));
  gl.attachShader(prog, shader(gl.FRAGMENT_SHADER,
    'precision mediump float; varying vec3 vc; void main() { gl_FragColor = vec4(vc, 1.0); }'));
  gl.linkProgram(prog);
  if (!gl.getProgramParameter(prog, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(prog));
  gl.useProgram(prog);
  var loc = { p: gl.getAttribLocation(prog, 'p'), n: gl.getAttribLocation(prog, 'n'), c: gl.getAttribLocation(prog, 'c'),
              m: gl.getUniformLocation(prog, 'm'), r: gl.getUniformLocation(prog, 'r'), lit: gl.getUniformLocation(prog, 'lit') };
  var buf = { p: gl.createBuffer(), n: gl.createBuffer(), c: gl.createBuffer(), e: gl.createBuffer() };
  var triangles = 0, segments = 0;
  var axisSel = document.getElementById('axis'), cutSlider = document.getElementById('cut'), worstBox = document.getElementById('worst');
  // The address's #fragment may set the view: figure (the canvas alone), axis=0..2, cut=0..1000,
  // worst=0|1, yaw=, pitch= (radians), zoom=.
  var opts = {};
  location.hash.slice(1).split('&').forEach(function (kv) { var p = kv.split('='); if (p[0]) opts[p[0]] = p.length > 1 ? p[1] : '1'; });
  if ('axis' in opts) axisSel.value = opts.axis;
  if ('cut' in opts) cutSlider.value = opts.cut;
  if ('worst' in opts) worstBox.checked = opts.worst !== '0';
  if ('figure' in opts) {
    Array.prototype.forEach.call(document.body.children, function (e) { if (e !== canvas) e.style.display = 'none'; });
    document.body.style.margin = '0'; canvas.style.border = 'none';
  }
  var worst = D.worst;
  function build() {
    var axis = +axisSel.value, t = +cutSlider.value / 1000;
    var cut = t >= 1 ? Infinity : lo[axis] + t * (hi[axis] - lo[axis]);
    var keep = new Uint8Array(nh);
    for (var h = 0; h < nh; h++) keep[h] = C[3 * h + axis] <= cut ? 1 : 0;
    var pos = [], nor = [], col = [], edge = [];
    function quad(h, f, rgb) {
      var q = FACES[f].map(function (i) { return H[8 * h + i]; });
      var x = q.map(function (v) { return [P[3 * v], P[3 * v + 1], P[3 * v + 2]]; });
      var d1 = [0, 1, 2].map(function (i) { return x[2][i] - x[0][i]; }), d2 = [0, 1, 2].map(function (i) { return x[3][i] - x[1][i]; });
      var n = [d1[1] * d2[2] - d1[2] * d2[1], d1[2] * d2[0] - d1[0] * d2[2], d1[0] * d2[1] - d1[1] * d2[0]];
      [0, 1, 2, 0, 2, 3].forEach(function (i) { pos.push(x[i][0], x[i][1], x[i][2]); nor.push(n[0], n[1], n[2]); col.push(rgb[0], rgb[1], rgb[2]); });
      for (var i = 0; i < 4; i++) { var y = x[i], z = x[(i + 1) % 4]; edge.push(y[0], y[1], y[2], z[0], z[1], z[2]); }
    }
    for (h = 0; h < nh; h++) {
      if (!keep[h]) continue;
      for (var f = 0; f < 6; f++) { var o = nb[6 * h + f]; if (o < 0 || !keep[o]) quad(h, f, ramp(S[h])); }
    }
    if (worstBox.checked) worst.forEach(function (h) { for (var f = 0; f < 6; f++) quad(h, f, [.2, .4, 1]); });
    gl.bindBuffer(gl.ARRAY_BUFFER, buf.p); gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(pos), gl.STATIC_DRAW);
    gl.bindBuffer(gl.ARRAY_BUFFER, buf.n); gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(nor), gl.STATIC_DRAW);
    gl.bindBuffer(gl.ARRAY_BUFFER, buf.c); gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(col), gl.STATIC_DRAW);
    gl.bindBuffer(gl.ARRAY_BUFFER, buf.e); gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(edge), gl.STATIC_DRAW);
    triangles = pos.length / 9; segments = edge.length / 6;
    draw();
    // Pixels the mesh covers (not the white background), for the tests and a sanity check.
    var px = new Uint8Array(4 * canvas.width * canvas.height), covered = 0;
    gl.readPixels(0, 0, canvas.width, canvas.height, gl.RGBA, gl.UNSIGNED_BYTE, px);
    for (var i = 0; i < px.length; i += 4) if (px[i] < 250 || px[i + 1] < 250 || px[i + 2] < 250) covered++;
    say('viewer-ready: ' + (triangles / 2) + ' faces drawn of ' + nh + ' hexes, ' + covered + ' pixels');
  }
  var yaw = 'yaw' in opts ? +opts.yaw : 0.6, pitch = 'pitch' in opts ? +opts.pitch : -0.5, zoom = 'zoom' in opts ? +opts.zoom : 1;
  function draw() {
    var w = canvas.clientWidth, h = canvas.clientHeight;
    if (canvas.width !== w || canvas.height !== h) { canvas.width = w; canvas.height = h; }
    gl.viewport(0, 0, canvas.width, canvas.height);
    gl.clearColor(1, 1, 1, 1); gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    gl.enable(gl.DEPTH_TEST); gl.depthFunc(gl.LEQUAL);
    var cy = Math.cos(yaw), sy = Math.sin(yaw), cp = Math.cos(pitch), sp = Math.sin(pitch);
    // rotation: yaw about z, then pitch about x (column-major 3x3)
    var R = [cy, sy * cp, sy * sp, -sy, cy * cp, cy * sp, 0, -sp, cp];
    var k = zoom / radius, aspect = canvas.width / Math.max(1, canvas.height);
    var sx = k / Math.max(aspect, 1), syy = k * Math.min(aspect, 1), sz = -0.5 * k;
    var M = new Float32Array(16);
    for (var col = 0; col < 3; col++) { M[4 * col] = R[3 * col] * sx; M[4 * col + 1] = R[3 * col + 1] * syy; M[4 * col + 2] = R[3 * col + 2] * sz; }
    for (var i = 0; i < 3; i++) {
      var s = 0; for (col = 0; col < 3; col++) s += M[4 * col + i] * centre[col];
      M[12 + i] = -s;
    }
    M[15] = 1;
    gl.uniformMatrix4fv(loc.m, false, M); gl.uniformMatrix3fv(loc.r, false, new Float32Array(R));
    gl.uniform1f(loc.lit, 1);
    gl.enable(gl.POLYGON_OFFSET_FILL); gl.polygonOffset(1, 1);
    [['p', buf.p], ['n', buf.n], ['c', buf.c]].forEach(function (b) {
      gl.bindBuffer(gl.ARRAY_BUFFER, b[1]); gl.enableVertexAttribArray(loc[b[0]]); gl.vertexAttribPointer(loc[b[0]], 3, gl.FLOAT, false, 0, 0);
    });
    if (triangles > 0) gl.drawArrays(gl.TRIANGLES, 0, 3 * triangles);
    gl.disable(gl.POLYGON_OFFSET_FILL);
    gl.uniform1f(loc.lit, 0);
    gl.disableVertexAttribArray(loc.n); gl.disableVertexAttribArray(loc.c);
    gl.vertexAttrib3f(loc.n, 0, 0, 1); gl.vertexAttrib3f(loc.c, .15, .15, .15);
    gl.bindBuffer(gl.ARRAY_BUFFER, buf.e); gl.vertexAttribPointer(loc.p, 3, gl.FLOAT, false, 0, 0);
    if (segments > 0) gl.drawArrays(gl.LINES, 0, 2 * segments);
  }
  var drag = null;
  canvas.addEventListener('mousedown', function (e) { drag = [e.clientX, e.clientY]; });
  window.addEventListener('mouseup', function () { drag = null; });
  window.addEventListener('mousemove', function (e) {
    if (!drag) return;
    yaw += 0.01 * (e.clientX - drag[0]); pitch += 0.01 * (e.clientY - drag[1]);
    drag = [e.clientX, e.clientY]; draw();
  });
  canvas.addEventListener('wheel', function (e) { e.preventDefault(); zoom *= Math.exp(-0.001 * e.deltaY); draw(); }, { passive: false });
  axisSel.addEventListener('change', build); cutSlider.addEventListener('input', build); worstBox.addEventListener('change', build);
  window.addEventListener('resize', draw);
  build();
})();
)JS";

}  // namespace

std::string html_report(const HexMesh& mesh, const QualityReport& q, const HtmlReportParams& params) {
  const std::string title = escape_html(params.title);
  std::string s = "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>" +
                  title + " - hexpeel quality report</title>\n<style>" + kStyle + "</style></head>\n<body>\n";
  s += "<h1>" + title + "</h1>\n<table>\n";
  auto row = [&](const std::string& k, const std::string& v) { s += "<tr><th>" + k + "</th><td>" + v + "</td></tr>\n"; };
  row("hexes", std::to_string(q.hexes));
  row("points", std::to_string(q.points));
  row("scaled Jacobian min / mean / max", fmt("%.4f", q.sj_min) + " / " + fmt("%.4f", q.sj_mean) + " / " + fmt("%.4f", q.sj_max));
  row("hexes with scaled Jacobian &le; 0", std::to_string(q.sj_count_nonpositive) +
                                           (q.sj_degenerate > 0 ? " (" + std::to_string(q.sj_degenerate) + " degenerate)" : ""));
  row("singular edges (interior / boundary)", std::to_string(q.singular_edges_interior) + " / " +
                                              std::to_string(q.singular_edges_boundary));
  row("topological ball", q.is_ball ? "yes" : "no: " + escape_html(q.topology_message));
  if (q.boundary_matches_surface.has_value())
    row("boundary equals surface", *q.boundary_matches_surface ? "yes" : "no: " + escape_html(q.boundary_message));
  s += "</table>\n<h2>Scaled Jacobian</h2>\n" + histogram_svg(q) + "\n";
  s += "<h2>Worst hexes</h2>\n<table><tr><th>hex</th><th>scaled Jacobian</th><th>centroid</th></tr>\n";
  for (const WorstHex& w : q.worst)
    s += "<tr><td>" + std::to_string(w.hex) + "</td><td>" + fmt("%.4f", w.scaled_jacobian) + "</td><td>" +
         fmt("%.6g", w.centroid.x()) + ", " + fmt("%.6g", w.centroid.y()) + ", " + fmt("%.6g", w.centroid.z()) + "</td></tr>\n";
  s += "</table>\n<h2>Mesh</h2>\n<div id=\"controls\">cut along <select id=\"axis\"><option value=\"0\">x</option>"
       "<option value=\"1\">y</option><option value=\"2\" selected>z</option></select> "
       "<input id=\"cut\" type=\"range\" min=\"0\" max=\"1000\" value=\"550\" aria-label=\"cut plane\"> "
       "<label><input id=\"worst\" type=\"checkbox\" checked> worst hexes in blue</label> "
       "<span class=\"legend\">scaled Jacobian 0 <span style=\"background:linear-gradient(90deg," +
       ramp(0.001) + "," + ramp(0.3) + "," + ramp(0.6) + "," + ramp(0.8) + "," + ramp(1.0) +
       ")\"></span> 1; drag to turn, wheel to zoom</span></div>\n"
       "<canvas id=\"view\" width=\"800\" height=\"560\"></canvas>\n<div id=\"status\">viewer-loading</div>\n";
  // The data: numbers only (and a note), so nothing in it can close the script element.
  const bool ids_ok = std::all_of(mesh.hexes.begin(), mesh.hexes.end(), [&](const Hex& h) {
    return std::all_of(h.begin(), h.end(), [&](int32_t v) { return v >= 0 && v < mesh.num_points(); });
  });
  const bool view = mesh.num_hexes() > 0 && mesh.num_hexes() <= params.max_view_hexes &&
                    q.per_hex_sj.size() == mesh.hexes.size() && ids_ok;
  s += "<script id=\"mesh-data\" type=\"application/json\">{\"view\":";
  s += view ? "true" : "false";
  if (!view) {
    const std::string note =
        mesh.num_hexes() == 0 ? "the mesh has no hexes"
        : !ids_ok             ? "some hex refers to a point that does not exist"
                              : "the mesh has " + std::to_string(mesh.num_hexes()) +
                                    " hexes, over the view's limit of " + std::to_string(params.max_view_hexes);
    s += ",\"note\":\"" + note + "\"";
  } else {
    s += ",\"points\":[";
    char buf[32];
    for (size_t i = 0; i < mesh.points.size(); ++i)
      for (int k = 0; k < 3; ++k) {
        const double x = mesh.points[i][k];
        std::snprintf(buf, sizeof(buf), "%.7g", std::isfinite(x) ? x : 0.0);
        if (i + k > 0) s += ',';
        s += buf;
      }
    s += "],\"hexes\":[";
    for (size_t h = 0; h < mesh.hexes.size(); ++h)
      for (int k = 0; k < 8; ++k) {
        if (h + k > 0) s += ',';
        s += std::to_string(mesh.hexes[h][k]);
      }
    s += "],\"sj\":[";
    for (size_t h = 0; h < q.per_hex_sj.size(); ++h) {
      if (h > 0) s += ',';
      std::snprintf(buf, sizeof(buf), "%.4f", std::isfinite(q.per_hex_sj[h]) ? q.per_hex_sj[h] : -2.0);
      s += buf;
    }
    s += "],\"worst\":[";
    for (size_t i = 0; i < q.worst.size(); ++i) s += (i ? "," : "") + std::to_string(q.worst[i].hex);
    s += "]";
  }
  s += "}</script>\n<script>";
  s += kScript;
  s += "</script>\n</body></html>\n";
  return s;
}

}  // namespace hexpeel
