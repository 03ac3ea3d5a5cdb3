// Front end of pic's self-contained HTML viewer (`pic view`). esbuild bundles this file with
// three.js into one IIFE at build time; the C++ library embeds that bundle in every page, so
// the page works offline. The page's data is a JSON block written by src/viewer.cpp:
//   <script id="pic-data" type="application/json">{
//     "info": string (JSON text for the stats panel), "offset": [x,y,z] (added back to all
//     coordinates, which are stored relative to it for float precision),
//     "positions": base64 Float32 xyz, "indices": base64 Uint32 (3 per triangle),
//     "cells": base64 Float32 (x, y, z, size per gray leaf), "points": base64 Float32 xyz }
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';

function decode(b64, Type) {
  if (!b64) return new Type(0);
  const bin = atob(b64);
  const bytes = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; i++) bytes[i] = bin.charCodeAt(i);
  return new Type(bytes.buffer);  // little-endian, as written by the library on x86/ARM
}

function element(tag, props = {}, parent = document.body) {
  const e = Object.assign(document.createElement(tag), props);
  parent.appendChild(e);
  return e;
}

function prettyInfo(text) {
  if (!text) return '';
  try {
    return JSON.stringify(JSON.parse(text), null, 2);
  } catch {
    return text;  // not JSON: show it as it is
  }
}

// The 12 edges of every cell as line segments: 24 endpoints per cell.
function cellEdges(cells) {
  const n = cells.length / 4;
  const out = new Float32Array(n * 24 * 3);
  let o = 0;
  for (let c = 0; c < n; c++) {
    const x = cells[4 * c], y = cells[4 * c + 1], z = cells[4 * c + 2], s = cells[4 * c + 3];
    for (let k = 0; k < 8; k++) {
      for (let bit = 1; bit < 8; bit <<= 1) {
        if (k & bit) continue;
        const j = k | bit;
        out[o++] = x + (k & 1) * s; out[o++] = y + ((k >> 1) & 1) * s; out[o++] = z + ((k >> 2) & 1) * s;
        out[o++] = x + (j & 1) * s; out[o++] = y + ((j >> 1) & 1) * s; out[o++] = z + ((j >> 2) & 1) * s;
      }
    }
  }
  return out;
}

function main() {
  const data = JSON.parse(document.getElementById('pic-data').textContent);
  const positions = decode(data.positions, Float32Array);
  const indices = decode(data.indices, Uint32Array);
  const cells = decode(data.cells, Float32Array);
  const points = decode(data.points, Float32Array);

  const ui = element('div', { id: 'ui' });
  element('div', { className: 'title', textContent: 'PIC viewer' }, ui);
  const toggle = (label, enabled) => {
    const row = element('label', {}, ui);
    const box = element('input', { type: 'checkbox', disabled: !enabled }, row);
    row.append(' ' + label);
    return box;
  };
  const cellBox = toggle(`octree cells (${cells.length / 4})`, cells.length > 0);
  const pointBox = toggle(`vertices (${points.length / 3})`, points.length > 0);
  element('div', {
    className: 'counts',
    textContent: `${indices.length / 3} triangles, ${positions.length / 3} vertices`,
  }, ui);
  element('pre', { id: 'stats', textContent: prettyInfo(data.info) });

  let renderer;
  try {
    renderer = new THREE.WebGLRenderer({ antialias: true });
  } catch (err) {
    element('div', { className: 'error', textContent: 'WebGL is not available: ' + err.message });
    return;
  }
  renderer.setPixelRatio(window.devicePixelRatio);
  renderer.setSize(window.innerWidth, window.innerHeight);
  renderer.setClearColor(0xfafafc);
  document.body.prepend(renderer.domElement);

  const scene = new THREE.Scene();
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(positions, 3));
  geometry.setIndex(new THREE.BufferAttribute(indices, 1));
  geometry.computeBoundingSphere();
  // Flat shading so sharp features read; the surface is pushed back slightly so cell edges
  // lying on it are not lost to z-fighting. Back faces (holes, inverted meshes) are warm.
  const surface = { flatShading: true, polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1 };
  scene.add(new THREE.Mesh(geometry, new THREE.MeshPhongMaterial({ ...surface, color: 0xa8bcdb, shininess: 20 })));
  scene.add(new THREE.Mesh(geometry, new THREE.MeshPhongMaterial({ ...surface, color: 0xdb8c6b, side: THREE.BackSide })));

  let cellLines = null;
  const pointCloud = new THREE.BufferGeometry();
  pointCloud.setAttribute('position', new THREE.BufferAttribute(points, 3));
  const dots = new THREE.Points(pointCloud, new THREE.PointsMaterial({ color: 0xd81e23, size: 4, sizeAttenuation: false }));
  dots.visible = false;
  scene.add(dots);

  // Frame the mesh, or the cells/points if there is no mesh.
  let sphere = geometry.boundingSphere;
  if (!(sphere && sphere.radius > 0)) {
    pointCloud.computeBoundingSphere();
    sphere = pointCloud.boundingSphere;
  }
  const radius = sphere && sphere.radius > 0 ? sphere.radius : 1;
  const center = sphere ? sphere.center : new THREE.Vector3();

  const camera = new THREE.PerspectiveCamera(35, window.innerWidth / window.innerHeight, radius / 100, radius * 100);
  camera.up.set(0, 0, 1);  // +Z up, as in `pic render`
  const dist = radius / Math.sin(THREE.MathUtils.degToRad(35 / 2)) * 1.3;
  camera.position.copy(center).add(new THREE.Vector3(1, -1, 1).normalize().multiplyScalar(dist));
  scene.add(new THREE.HemisphereLight(0xffffff, 0x8088a0, 1.5));
  // The key light and its target are children of the camera, so the light follows the view.
  const key = new THREE.DirectionalLight(0xffffff, 2.2);
  key.position.set(-0.3, 0.6, 1);
  key.target.position.set(0, 0, -1);
  camera.add(key, key.target);
  scene.add(camera);

  const controls = new OrbitControls(camera, renderer.domElement);
  controls.target.copy(center);
  controls.update();

  const draw = () => renderer.render(scene, camera);
  controls.addEventListener('change', draw);
  window.addEventListener('resize', () => {
    camera.aspect = window.innerWidth / window.innerHeight;
    camera.updateProjectionMatrix();
    renderer.setSize(window.innerWidth, window.innerHeight);
    draw();
  });
  cellBox.addEventListener('change', () => {
    if (!cellLines) {  // built on first use: large trees have many cells
      const g = new THREE.BufferGeometry();
      g.setAttribute('position', new THREE.BufferAttribute(cellEdges(cells), 3));
      cellLines = new THREE.LineSegments(g, new THREE.LineBasicMaterial({ color: 0x1e2230, transparent: true, opacity: 0.8 }));
      scene.add(cellLines);
    }
    cellLines.visible = cellBox.checked;
    draw();
  });
  pointBox.addEventListener('change', () => {
    dots.visible = pointBox.checked;
    draw();
  });
  draw();
  window.picViewerReady = true;  // for automated checks
}

main();
