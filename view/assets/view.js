// rigcal live view: a three.js scene fed by the server's WebSocket (/ws). Binary messages carry float32
// points (see view/include/rigcal/view/update_encoding.hpp), text messages JSON status. Read-only.
'use strict';
(function () {
  const KIND = { map: 1, trajectory: 2, candidate: 3, selected: 4, before: 5, after: 6 };
  const STRIDE = { 1: 3, 2: 4, 3: 4, 4: 3, 5: 3, 6: 3 };
  const CODE = { frame: 0, keyframe: 1, stopped: 2, lost: 3 };
  const LANE_COLORS = [0x00e5ff, 0xff9100, 0xd500f9, 0x76ff03, 0xffea00, 0xff4081];
  const BEFORE_COLOR = 0xff5252;

  // What the page shows, readable by tests (window.rigcalView).
  const state = {
    connected: false, finished: false, lidars: [], counters: null, report: null, showAfter: true,
    mapPoints: 0, poses: 0, candidates: 0, selected: {}, cloudPoints: { before: 0, after: 0 }, messages: 0,
  };
  window.rigcalView = state;

  const canvas = document.getElementById('scene');
  const renderer = new THREE.WebGLRenderer({ canvas: canvas, antialias: false, preserveDrawingBuffer: true });
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0x111418);
  const camera = new THREE.PerspectiveCamera(60, 1, 0.1, 10000);
  camera.up.set(0, 0, 1);  // the map frame is z-up
  camera.position.set(-25, -25, 35);
  const controls = new THREE.OrbitControls(camera, renderer.domElement);
  controls.target.set(0, 0, 0);
  controls.update();
  let fitted = false;

  function resize() {
    const w = window.innerWidth, h = window.innerHeight;
    renderer.setSize(w, h, false);
    camera.aspect = w / h;
    camera.updateProjectionMatrix();
  }
  window.addEventListener('resize', resize);
  resize();

  function pointsObject(positions, colors, size, color) {
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(positions, 3));
    const opts = { size: size, sizeAttenuation: false };
    if (colors) { g.setAttribute('color', new THREE.BufferAttribute(colors, 3)); opts.vertexColors = THREE.VertexColors; }
    else opts.color = color;
    return new THREE.Points(g, new THREE.PointsMaterial(opts));
  }

  // The map, coloured by height: blue (ground) to red (high).
  const heightColor = new THREE.Color();
  function addMap(values) {
    const n = values.length / 3;
    const colors = new Float32Array(values.length);
    for (let i = 0; i < n; ++i) {
      const t = Math.min(1, Math.max(0, (values[3 * i + 2] + 2.5) / 6));
      heightColor.setHSL(0.66 * (1 - t), 1, 0.5);
      colors[3 * i] = heightColor.r; colors[3 * i + 1] = heightColor.g; colors[3 * i + 2] = heightColor.b;
    }
    scene.add(pointsObject(new Float32Array(values), colors, 2));
    state.mapPoints += n;
    if (!fitted) fit(values);
  }

  function fit(values) {
    const n = values.length / 3;
    if (n === 0) return;
    let x = 0, y = 0, z = 0;
    for (let i = 0; i < n; ++i) { x += values[3 * i]; y += values[3 * i + 1]; z += values[3 * i + 2]; }
    controls.target.set(x / n, y / n, z / n);
    camera.position.set(x / n - 25, y / n - 25, z / n + 35);
    controls.update();
    fitted = true;
  }

  // The trajectory: a line through every pose, and markers for keyframes, stops and losses.
  const track = { all: [], keyframe: [], stopped: [], lost: [], objects: [] };
  function addPoses(values) {
    for (let i = 0; i < values.length; i += 4) {
      const p = [values[i], values[i + 1], values[i + 2]];
      track.all.push(...p);
      const code = values[i + 3];
      if (code === CODE.keyframe) track.keyframe.push(...p);
      else if (code === CODE.stopped) track.stopped.push(...p);
      else if (code === CODE.lost) track.lost.push(...p);
      state.poses += 1;
    }
    for (const o of track.objects) { scene.remove(o); o.geometry.dispose(); o.material.dispose(); }
    const line = new THREE.BufferGeometry();
    line.setAttribute('position', new THREE.BufferAttribute(new Float32Array(track.all), 3));
    track.objects = [
      new THREE.Line(line, new THREE.LineBasicMaterial({ color: 0x90caf9 })),
      pointsObject(new Float32Array(track.keyframe), null, 5, 0xffffff),
      pointsObject(new Float32Array(track.stopped), null, 9, 0xffd600),
      pointsObject(new Float32Array(track.lost), null, 11, 0xff1744),
    ];
    for (const o of track.objects) scene.add(o);
  }

  // Per calibration lidar: its candidate frames (small) and the frames the selector holds (large).
  const lanes = {};
  function lane(i) {
    if (!lanes[i]) lanes[i] = { candidates: [], candidateObject: null, selectedObject: null, before: [], after: [] };
    return lanes[i];
  }
  function laneColor(i) { return LANE_COLORS[i % LANE_COLORS.length]; }
  function replace(old, next) { if (old) { scene.remove(old); old.geometry.dispose(); old.material.dispose(); } scene.add(next); return next; }
  function addCandidate(i, values) {
    const l = lane(i);
    for (let k = 0; k < values.length; k += 4) l.candidates.push(values[k], values[k + 1], values[k + 2] + 0.3);
    l.candidateObject = replace(l.candidateObject, pointsObject(new Float32Array(l.candidates), null, 4, laneColor(i)));
    state.candidates += values.length / 4;
  }
  function setSelected(i, values) {
    const l = lane(i);
    const lifted = new Float32Array(values.length);
    for (let k = 0; k < values.length; k += 3) { lifted[k] = values[k]; lifted[k + 1] = values[k + 1]; lifted[k + 2] = values[k + 2] + 0.6; }
    l.selectedObject = replace(l.selectedObject, pointsObject(lifted, null, 13, laneColor(i)));
    state.selected[i] = values.length / 3;
  }

  // After calibration: each lidar's points through the initial guess (red) and the result (its colour).
  const toggle = document.getElementById('toggle');
  function addCloud(i, values, after) {
    const obj = pointsObject(new Float32Array(values), null, 2, after ? laneColor(i) : BEFORE_COLOR);
    obj.visible = after === state.showAfter;
    (after ? lane(i).after : lane(i).before).push(obj);
    scene.add(obj);
    state.cloudPoints[after ? 'after' : 'before'] += values.length / 3;
    toggle.disabled = false;
    showing();
  }
  function showing() {
    document.getElementById('showing').textContent = state.showAfter ? 'showing: after (calibrated)' : 'showing: before (initial guess)';
  }
  toggle.addEventListener('click', function () {
    state.showAfter = !state.showAfter;
    for (const i in lanes) {
      for (const o of lanes[i].before) o.visible = !state.showAfter;
      for (const o of lanes[i].after) o.visible = state.showAfter;
    }
    showing();
  });

  function setText(el, text) { if (el.textContent !== text) el.textContent = text; }

  function showCounters(c) {
    state.counters = c;
    state.finished = state.finished || c.finished;
    for (const el of document.querySelectorAll('[data-counter]')) {
      const key = el.getAttribute('data-counter');
      if (!(key in c)) continue;
      setText(el, key === 'budget_fill' ? Math.round(100 * c.budget_fill) + '%' : String(c[key]));
    }
    const table = document.getElementById('lidars');
    table.textContent = '';
    (c.lidars || []).forEach(function (l, i) {
      const row = table.insertRow();
      const name = row.insertCell();
      name.textContent = l.sensor;
      name.style.color = '#' + laneColor(i).toString(16).padStart(6, '0');
      const v = row.insertCell();
      v.setAttribute('data-lidar', l.sensor);
      v.textContent = l.selected + '/' + l.budget + ' (cand ' + l.candidates + ')' + (l.handed_over ? ' ✓' : '');
    });
    setText(document.getElementById('status'), c.finished ? 'finished' : (state.connected ? 'live' : 'disconnected'));
  }

  function deg(r) { return (r * 180 / Math.PI).toFixed(2); }
  function showReport(r) {
    state.report = r;
    const table = document.getElementById('summary');
    table.textContent = '';
    const head = table.insertRow();
    for (const h of ['lidar', 'verdict', 'x m', 'y m', 'z m', 'roll °', 'pitch °', 'yaw °', 'Δt m', 'Δr °', 'rmse m', 'inliers'])
      head.appendChild(document.createElement('th')).textContent = h;
    for (const l of r.lidars || []) {
      const row = table.insertRow();
      const res = l.result || {}, ch = l.change_from_initial || {}, sc = l.final_score || {};
      const cells = [l.sensor, l.verdict || (l.ok ? 'ok' : 'failed'),
        (res.x || 0).toFixed(3), (res.y || 0).toFixed(3), (res.z || 0).toFixed(3),
        deg(res.roll || 0), deg(res.pitch || 0), deg(res.yaw || 0),
        (ch.translation_m || 0).toFixed(3), (ch.rotation_deg || 0).toFixed(2),
        (sc.rmse_m || 0).toFixed(4), (sc.inlier_ratio || 0).toFixed(2)];
      for (const c of cells) row.insertCell().textContent = c;
    }
    // `rigcal view OUT_DIR` has no live counters: show the report's.
    if (!state.counters && r.input) {
      for (const el of document.querySelectorAll('[data-counter]')) {
        const key = el.getAttribute('data-counter');
        if (key in r.input) setText(el, String(r.input[key]));
      }
    }
    if (r.status) setText(document.getElementById('status'), 'finished: ' + r.status);
    state.finished = true;
  }

  function onBinary(buffer) {
    const view = new DataView(buffer);
    const kind = view.getUint8(0), laneIndex = view.getUint8(1), count = view.getUint32(4, true);
    const stride = STRIDE[kind];
    if (!stride || buffer.byteLength !== 8 + 4 * stride * count) return;
    const values = new Float32Array(buffer, 8, stride * count);
    if (kind === KIND.map) addMap(values);
    else if (kind === KIND.trajectory) addPoses(values);
    else if (kind === KIND.candidate) addCandidate(laneIndex, values);
    else if (kind === KIND.selected) setSelected(laneIndex, values);
    else if (kind === KIND.before) addCloud(laneIndex, values, false);
    else if (kind === KIND.after) addCloud(laneIndex, values, true);
    if (!fitted && (kind === KIND.before || kind === KIND.after)) fit(values);
  }

  function onText(text) {
    const m = JSON.parse(text);
    if (m.type === 'counters') showCounters(m);
    else if (m.type === 'lidars') state.lidars = m.names;
    else if (m.type === 'report') showReport(m.report);
  }

  function connect() {
    const ws = new WebSocket((location.protocol === 'https:' ? 'wss://' : 'ws://') + location.host + '/ws');
    ws.binaryType = 'arraybuffer';
    ws.onopen = function () { state.connected = true; setText(document.getElementById('status'), 'live'); };
    ws.onmessage = function (e) {
      state.messages += 1;
      if (typeof e.data === 'string') onText(e.data);
      else onBinary(e.data);
    };
    ws.onclose = function () {
      state.connected = false;
      if (!state.finished) setText(document.getElementById('status'), 'disconnected (run ended?)');
    };
  }

  function frame() {
    controls.update();
    renderer.render(scene, camera);
    requestAnimationFrame(frame);
  }
  showing();
  connect();
  frame();
})();
