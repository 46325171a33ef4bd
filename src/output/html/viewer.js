// meshclash HTML report viewer: plain JavaScript and WebGL 2, no library, nothing fetched.
// Reads the JSON in #meshclash-data (written by src/output/html.rs), fills the clash table and
// draws the parts: orbit camera (drag: rotate, shift/right drag: pan, wheel: zoom), flat shading
// from screen-space derivatives, part A orange, part B blue, others faded, contact segments
// magenta and the witness segment green, both on top.
(function () {
  'use strict';
  var data = JSON.parse(document.getElementById('meshclash-data').textContent);
  var COLOR = {
    a: [1.0, 0.5, 0.05], b: [0.12, 0.47, 0.8], faded: [0.6, 0.62, 0.66],
    seg: [0.86, 0.08, 0.6], wit: [0.1, 0.7, 0.2], box: [0.55, 0.57, 0.6]
  };
  var KIND_RANK = { 'crossing': 0, 'contained': 0, 'volumes overlap': 0, 'touching': 1, 'clearance': 2, 'closest': 3 };

  function decode(s, Type) {
    var bin = atob(s), u8 = new Uint8Array(bin.length);
    for (var i = 0; i < bin.length; i++) u8[i] = bin.charCodeAt(i);
    return new Type(u8.buffer);
  }
  function fmt(x) {
    if (x === null || x === undefined) return '';
    if (x === 0) return '0';
    var a = Math.abs(x);
    return (a >= 1e5 || a < 1e-3) ? x.toExponential(3) : String(+x.toPrecision(5));
  }
  function unit() { return data.units === 'model' ? '' : ' ' + data.units; }

  // ---------- clash table ----------
  var rows = data.rows.map(function (r, i) {
    r.rank = i + 1;
    r.measure = r.penetration !== null ? r.penetration : (r.distance === null ? Infinity : r.distance);
    r.status = r.status || '';
    return r;
  });
  var tbody = document.querySelector('#clashes tbody');
  var filterBox = document.getElementById('filter');
  var sortKey = 'rank', sortDir = 1, selected = -1;

  function measureText(r) {
    var o = r.overlap ? ', overlap ' + r.overlap.map(fmt).join(' \u00d7 ') + unit() : '';
    if (r.penetration !== null) {
      // An exact convex depth, or a sampled lower bound.
      if (r.penetration_exact) return 'depth ' + fmt(r.penetration) + unit() + ' (exact)' + o;
      return 'depth \u2265 ' + fmt(r.penetration) + unit() + o;
    }
    if (r.distance === null) return o.slice(2);
    return (r.distance === 0 ? 'contact' : 'd ' + fmt(r.distance) + unit()) + o;
  }
  function cell(tr, text, cls) {
    var td = document.createElement('td');
    td.textContent = text;
    if (cls) td.className = cls;
    tr.appendChild(td);
    return td;
  }
  function renderTable() {
    var q = filterBox.value.trim().toLowerCase();
    var list = rows.filter(function (r) {
      return !q || (r.a_name + '\u0000' + r.b_name).toLowerCase().indexOf(q) >= 0;
    });
    list.sort(function (x, y) {
      var a = x[sortKey], b = y[sortKey];
      if (typeof a === 'string') return sortDir * a.localeCompare(b) || x.rank - y.rank;
      return sortDir * (a - b) || x.rank - y.rank;
    });
    tbody.textContent = '';
    list.forEach(function (r) {
      var tr = document.createElement('tr');
      tr.dataset.row = String(r.rank - 1);
      if (r.rank - 1 === selected) tr.className = 'selected';
      cell(tr, String(r.rank));
      cell(tr, r.a_name, 'name a').title = r.a_name;
      cell(tr, r.b_name, 'name b').title = r.b_name;
      cell(tr, r.kind, 'kind k-' + r.kind.replace(' ', '-'));
      cell(tr, r.pairs + (r.crossing && r.crossing !== r.pairs ? ' (' + r.crossing + ' crossing)' : ''), 'num');
      cell(tr, measureText(r), 'num');
      cell(tr, r.status, 'status s-' + (r.status || 'none'));
      tr.addEventListener('click', function () { select(r.rank - 1); });
      tbody.appendChild(tr);
    });
    document.getElementById('count').textContent =
      list.length + ' of ' + rows.length + ' clash' + (rows.length === 1 ? '' : 'es') +
      ' · ' + data.triangles_shown + ' of ' + data.triangles_total + ' triangles drawn';
    document.querySelectorAll('#clashes th').forEach(function (th) {
      th.className = th.dataset.key === sortKey ? (sortDir > 0 ? 'asc' : 'desc') : '';
    });
  }
  document.querySelectorAll('#clashes th').forEach(function (th) {
    th.addEventListener('click', function () {
      var k = th.dataset.key;
      if (k === sortKey) sortDir = -sortDir; else { sortKey = k; sortDir = 1; }
      renderTable();
    });
  });
  filterBox.addEventListener('input', renderTable);
  var xray = document.getElementById('xray');
  xray.addEventListener('change', function () { dirty = true; });
  document.getElementById('overview').addEventListener('click', function () { select(-1); });

  // ---------- WebGL ----------
  var canvas = document.getElementById('gl');
  var gl = canvas.getContext('webgl2', { antialias: true, preserveDrawingBuffer: true });
  var hasGL = !!gl;
  var VS = '#version 300 es\nin vec3 pos;uniform mat4 mvp;uniform mat4 mv;uniform float psize;out vec3 vp;' +
    'void main(){vp=(mv*vec4(pos,1.0)).xyz;gl_Position=mvp*vec4(pos,1.0);gl_PointSize=psize;}';
  var FS_MESH = '#version 300 es\nprecision highp float;in vec3 vp;uniform vec4 color;out vec4 o;' +
    'void main(){vec3 n=normalize(cross(dFdx(vp),dFdy(vp)));float l=0.3+0.7*abs(n.z);o=vec4(color.rgb*l,color.a);}';
  var FS_FLAT = '#version 300 es\nprecision highp float;in vec3 vp;uniform vec4 color;out vec4 o;' +
    'void main(){o=color;}';

  function program(vs, fs) {
    function sh(type, src) {
      var s = gl.createShader(type);
      gl.shaderSource(s, src);
      gl.compileShader(s);
      if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
      return s;
    }
    var p = gl.createProgram();
    gl.attachShader(p, sh(gl.VERTEX_SHADER, vs));
    gl.attachShader(p, sh(gl.FRAGMENT_SHADER, fs));
    gl.bindAttribLocation(p, 0, 'pos');
    gl.linkProgram(p);
    if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(p));
    return { p: p, mvp: gl.getUniformLocation(p, 'mvp'), mv: gl.getUniformLocation(p, 'mv'),
      color: gl.getUniformLocation(p, 'color'), psize: gl.getUniformLocation(p, 'psize') };
  }
  function buffer(array, target) {
    var b = gl.createBuffer();
    gl.bindBuffer(target, b);
    gl.bufferData(target, array, gl.STATIC_DRAW);
    return b;
  }
  function geometry(positions, indices) {
    var vao = gl.createVertexArray();
    gl.bindVertexArray(vao);
    buffer(positions, gl.ARRAY_BUFFER);
    gl.enableVertexAttribArray(0);
    gl.vertexAttribPointer(0, 3, gl.FLOAT, false, 0, 0);
    if (indices) buffer(indices, gl.ELEMENT_ARRAY_BUFFER);
    gl.bindVertexArray(null);
    return { vao: vao, count: indices ? indices.length : positions.length / 3, indexed: !!indices };
  }
  function boxLines(bx) {
    var a = bx[0], b = bx[1], p = [], c = [];
    for (var i = 0; i < 8; i++) c.push([i & 1 ? b[0] : a[0], i & 2 ? b[1] : a[1], i & 4 ? b[2] : a[2]]);
    [[0, 1], [2, 3], [4, 5], [6, 7], [0, 2], [1, 3], [4, 6], [5, 7], [0, 4], [1, 5], [2, 6], [3, 7]]
      .forEach(function (e) { p.push.apply(p, c[e[0]]); p.push.apply(p, c[e[1]]); });
    return new Float32Array(p);
  }

  // ---------- matrices (column-major) ----------
  function mul(a, b) {
    var o = new Float32Array(16);
    for (var c = 0; c < 4; c++) for (var r = 0; r < 4; r++) {
      var s = 0;
      for (var k = 0; k < 4; k++) s += a[k * 4 + r] * b[c * 4 + k];
      o[c * 4 + r] = s;
    }
    return o;
  }
  function perspective(fovy, aspect, near, far) {
    var f = 1 / Math.tan(fovy / 2), o = new Float32Array(16);
    o[0] = f / aspect; o[5] = f; o[10] = (far + near) / (near - far); o[11] = -1;
    o[14] = 2 * far * near / (near - far);
    return o;
  }
  function sub(a, b) { return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]; }
  function cross(a, b) { return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]; }
  function norm(a) { var l = Math.hypot(a[0], a[1], a[2]) || 1; return [a[0] / l, a[1] / l, a[2] / l]; }
  function dot(a, b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
  function lookAt(eye, target, up) {
    var z = norm(sub(eye, target)), x = norm(cross(up, z)), y = cross(z, x);
    return new Float32Array([x[0], y[0], z[0], 0, x[1], y[1], z[1], 0, x[2], y[2], z[2], 0,
      -dot(x, eye), -dot(y, eye), -dot(z, eye), 1]);
  }

  // ---------- scene ----------
  var FOV = 0.7;
  var up = data.up === 'z' ? [0, 0, 1] : [0, 1, 0];
  var cam = { target: [0, 0, 0], dist: 1, yaw: 0.7, pitch: 0.45, radius: 1 };
  var parts = [], rowGeo = [], progs = null, sceneRadius = 1, dirty = true, frames = 0;

  function boxUnion(boxes) {
    var lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
    boxes.forEach(function (b) {
      for (var k = 0; k < 3; k++) { lo[k] = Math.min(lo[k], b[0][k]); hi[k] = Math.max(hi[k], b[1][k]); }
    });
    return [lo, hi];
  }
  function diag(b) { return Math.hypot(b[1][0] - b[0][0], b[1][1] - b[0][1], b[1][2] - b[0][2]); }

  function eye() {
    // Orbit around `up`: yaw about it, pitch towards it.
    var u = up, f = up[2] ? [0, -1, 0] : [0, 0, 1], r = cross(u, f);
    var cp = Math.cos(cam.pitch), sp = Math.sin(cam.pitch), cy = Math.cos(cam.yaw), sy = Math.sin(cam.yaw);
    var d = [0, 1, 2].map(function (k) { return cam.dist * (cp * (cy * f[k] + sy * r[k]) + sp * u[k]); });
    return [cam.target[0] + d[0], cam.target[1] + d[1], cam.target[2] + d[2]];
  }
  function frame(box, minRadius) {
    var r = Math.max(diag(box) / 2, minRadius || 0, 1e-9);
    cam.target = [0, 1, 2].map(function (k) { return (box[0][k] + box[1][k]) / 2; });
    cam.radius = r;
    cam.dist = r / Math.sin(FOV / 2) * 1.1;
    dirty = true;
  }

  function draw() {
    dirty = false;
    var w = canvas.clientWidth, h = canvas.clientHeight, dpr = window.devicePixelRatio || 1;
    if (canvas.width !== Math.round(w * dpr) || canvas.height !== Math.round(h * dpr)) {
      canvas.width = Math.round(w * dpr); canvas.height = Math.round(h * dpr);
    }
    gl.viewport(0, 0, canvas.width, canvas.height);
    gl.clearColor(1, 1, 1, 1);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    var far = cam.dist + sceneRadius * 4, near = Math.max(cam.dist - sceneRadius * 2, cam.dist * 1e-3, far * 1e-6);
    var view = lookAt(eye(), cam.target, up);
    var mvp = mul(perspective(FOV, canvas.width / Math.max(canvas.height, 1), near, far), view);
    var row = selected >= 0 ? rows[selected] : null;

    function use(pr, color, alpha, psize) {
      gl.useProgram(pr.p);
      gl.uniformMatrix4fv(pr.mvp, false, mvp);
      gl.uniformMatrix4fv(pr.mv, false, view);
      gl.uniform4f(pr.color, color[0], color[1], color[2], alpha);
      gl.uniform1f(pr.psize, psize || 1);
    }
    function mesh(g, mode) {
      gl.bindVertexArray(g.vao);
      if (g.indexed) gl.drawElements(mode, g.count, gl.UNSIGNED_INT, 0); else gl.drawArrays(mode, 0, g.count);
    }
    // Drawn first (under the other with see-through): the larger part of the selected clash, or in the overview a part that is
    // the larger one of some clash.
    function see(i) {
      if (row) return row.a !== row.b && i === (diag(parts[row.a].bounds) >= diag(parts[row.b].bounds) ? row.a : row.b);
      return parts[i].container;
    }
    function role(i) {
      if (row) return i === row.a ? 'a' : (i === row.b ? 'b' : null);
      return parts[i].involved ? parts[i].side : null;
    }
    // Context first, faded and without depth writes, so it never washes out the clash; then the
    // clash parts: the larger of each pair (the container) first, then, with "see through", the
    // smaller one over it (its own depth kept).
    gl.enable(gl.DEPTH_TEST);
    gl.enable(gl.BLEND);
    gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA);
    gl.depthMask(false);
    parts.forEach(function (p, i) {
      if (role(i)) return;
      if (p.geo) { use(progs.mesh, COLOR.faded, 0.12); mesh(p.geo, gl.TRIANGLES); }
      else { use(progs.flat, COLOR.box, 0.35); mesh(p.box, gl.LINES); }
    });
    gl.depthMask(true);
    gl.disable(gl.BLEND);
    parts.forEach(function (p, i) {
      var r = role(i);
      if (r && p.geo && see(i)) { use(progs.mesh, COLOR[r], 1); mesh(p.geo, gl.TRIANGLES); }
    });
    // See-through: the contained parts are drawn over their containers.
    if (xray.checked) gl.clear(gl.DEPTH_BUFFER_BIT);
    parts.forEach(function (p, i) {
      var r = role(i);
      if (r && p.geo && !see(i)) { use(progs.mesh, COLOR[r], 1); mesh(p.geo, gl.TRIANGLES); }
    });
    gl.disable(gl.DEPTH_TEST);
    rowGeo.forEach(function (g, i) {
      if (row && i !== selected) return;
      if (g.seg) { use(progs.flat, COLOR.seg, 1, row ? 5 : 3); mesh(g.seg, gl.LINES); mesh(g.seg, gl.POINTS); }
      if (g.wit) { use(progs.flat, COLOR.wit, 1, 7); mesh(g.wit, gl.LINES); mesh(g.wit, gl.POINTS); }
    });
    gl.depthMask(true);
    frames++;
    document.body.dataset.frames = String(frames);
  }
  function loop() {
    if (dirty) draw();
    requestAnimationFrame(loop);
  }

  function legend() {
    var el = document.getElementById('legend'), row = selected >= 0 ? rows[selected] : null;
    el.textContent = '';
    function item(color, text) {
      var s = document.createElement('span'), sw = document.createElement('i');
      sw.style.background = 'rgb(' + color.map(function (c) { return Math.round(c * 255); }).join(',') + ')';
      s.appendChild(sw); s.appendChild(document.createTextNode(text)); el.appendChild(s);
    }
    if (row) {
      var pa = parts[row.a], pb = parts[row.b];
      item(COLOR.a, 'A ' + row.a_name + (pa.clipped ? ' (clipped)' : ''));
      item(COLOR.b, 'B ' + row.b_name + (pb.clipped ? ' (clipped)' : ''));
      if (row.segments.length) item(COLOR.seg, (row.kind === 'clearance' ? 'closest points ' : 'contact segments ') +
        row.segments.length / 6 + (row.segments_left_off ? ' (' + row.segments_left_off + ' more not drawn)' : ''));
      if (row.witness.length) item(COLOR.wit, 'witness ' + (row.distance !== null ? 'd ' + fmt(row.distance) + unit() : ''));
    } else {
      item(COLOR.a, 'A side of a clash');
      item(COLOR.b, 'B side of a clash');
      item(COLOR.faded, 'other parts');
      item(COLOR.seg, 'contact segments');
      item(COLOR.wit, 'closest points');
    }
  }

  function select(i) {
    selected = i;
    if (!hasGL) {
      // No viewer: the table alone.
    } else if (i < 0) {
      var inv = parts.filter(function (p) { return p.involved; });
      var box = boxUnion((inv.length ? inv : parts).map(function (p) { return p.bounds; }));
      frame(box, 0);
    } else {
      var r = rows[i], small = Math.min(diag(parts[r.a].bounds), diag(parts[r.b].bounds));
      frame(r.bounds, Math.max(0.12 * small, diag(r.bounds) * 0.8));
    }
    renderTable();
    legend();
    document.body.dataset.selected = i < 0 ? '' : rows[i].id;
  }

  function initGL() {
    progs = { mesh: program(VS, FS_MESH), flat: program(VS, FS_FLAT) };
    parts = data.parts.map(function (p) {
      var o = { name: p.name, side: p.side, involved: p.involved, clipped: p.clipped, bounds: p.bounds, geo: null };
      if (p.shown > 0) o.geo = geometry(decode(p.positions, Float32Array), decode(p.indices, Uint32Array));
      else o.box = geometry(boxLines(p.bounds), null);
      return o;
    });
    rowGeo = rows.map(function (r) {
      return {
        seg: r.segments.length ? geometry(new Float32Array(r.segments), null) : null,
        wit: r.witness.length ? geometry(new Float32Array(r.witness), null) : null
      };
    });
    rows.forEach(function (r) {
      if (r.a === r.b) return;
      parts[diag(parts[r.a].bounds) >= diag(parts[r.b].bounds) ? r.a : r.b].container = true;
    });
    sceneRadius = Math.max(diag(boxUnion(parts.map(function (p) { return p.bounds; }))) / 2, 1e-9);

    var drag = null;
    canvas.addEventListener('contextmenu', function (e) { e.preventDefault(); });
    canvas.addEventListener('pointerdown', function (e) {
      drag = { x: e.clientX, y: e.clientY, pan: e.button !== 0 || e.shiftKey };
      canvas.setPointerCapture(e.pointerId);
    });
    canvas.addEventListener('pointermove', function (e) {
      if (!drag) return;
      var dx = e.clientX - drag.x, dy = e.clientY - drag.y;
      drag.x = e.clientX; drag.y = e.clientY;
      if (drag.pan) {
        var ev = eye(), z = norm(sub(ev, cam.target)), x = norm(cross(up, z)), y = cross(z, x);
        var s = 2 * cam.dist * Math.tan(FOV / 2) / canvas.clientHeight;
        for (var k = 0; k < 3; k++) cam.target[k] += (-dx * x[k] + dy * y[k]) * s;
      } else {
        cam.yaw -= dx * 0.008;
        cam.pitch = Math.max(-1.55, Math.min(1.55, cam.pitch + dy * 0.008));
      }
      dirty = true;
    });
    canvas.addEventListener('pointerup', function () { drag = null; });
    canvas.addEventListener('wheel', function (e) {
      e.preventDefault();
      cam.dist *= Math.exp(e.deltaY * 0.001);
      dirty = true;
    }, { passive: false });
    window.addEventListener('resize', function () { dirty = true; });
  }

  if (hasGL) {
    initGL();
  } else {
    document.getElementById('nogl').hidden = false;
    canvas.hidden = true;
  }
  select(-1);
  if (hasGL) {
    draw();
    requestAnimationFrame(loop);
  }
  document.body.dataset.ready = hasGL ? 'webgl' : 'nogl';
})();
