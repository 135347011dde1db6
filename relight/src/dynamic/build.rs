//! Building a dynamic scene: its shapes, their occlusion fields (computed or read from the
//! field store) and each object's own transport at its file placement.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::dynamic::fields::file::{FieldOrigin, FieldStore};
use crate::dynamic::fields::{FieldOptions, OcclusionField};
use crate::precompute::shard::Shard;
use crate::precompute::sparse::SparseRows;
use crate::precompute::visibility::{VisibilityOptions, ray_offset, vertex_major};
use crate::scene::shapes::merge;
use crate::scene::validate::MemoryBudget;
use crate::scene::{MeshAsset, SceneFile, ground_plane_under};
use crate::shade::glossy::GlossyOptions;
use crate::{Error, Result};
use crate::{Generator, Mesh, SceneBvh, SceneError};

use crate::dynamic::{
    BuildReport, DynamicOptions, DynamicScene, Object, Placement, place_mesh, turned,
};

impl DynamicScene {
    /// Builds or loads, in `store`, the occlusion fields of shard `shard`'s share of the
    /// distinct shapes of the scene file at `path` ([`Shard::range`] of them, in order of first
    /// use); a shape whose file already matches is loaded, not built again. Fields are one
    /// file a shape and independent, so the shards of `relight scene --fields-dir DIR --shard
    /// I/N` need no merge: a render with the same `DIR` then loads every shape's file.
    ///
    /// ```
    /// use haarshift_relight::dynamic::{DynamicOptions, DynamicScene};
    /// use haarshift_relight::dynamic::fields::file::FieldStore;
    /// use haarshift_relight::precompute::shard::Shard;
    /// use haarshift::faces::{ParamKind, Parameterization};
    /// let dir = tempfile::tempdir().unwrap();
    /// let scene = dir.path().join("two.json");
    /// std::fs::write(&scene, r#"{"objects": [{"generator": {"sphere": {"cells": 2}}},
    ///                                        {"generator": {"table": {"cells": 1}}}]}"#).unwrap();
    /// let mut options = DynamicOptions::new(Parameterization::new(ParamKind::LatLong, 4).unwrap());
    /// (options.field.circles, options.field.circle_points) = (3, 6);
    /// (options.field.shells, options.field.shell_grid) = (2, 2);
    /// let mut store = FieldStore::new(dir.path(), false);
    /// let second = Shard::new(1, 2).unwrap();
    /// let report = DynamicScene::build_fields(&scene, &options, &mut store, second).unwrap();
    /// assert_eq!(report.fields_written, 1);
    /// assert!(dir.path().join("table-cells-1.hsf").exists());
    /// assert!(!dir.path().join("sphere-cells-2.hsf").exists());
    /// ```
    pub fn build_fields(
        path: &Path,
        options: &DynamicOptions,
        store: &mut FieldStore,
        shard: Shard,
    ) -> Result<BuildReport> {
        let mut build = || {
            options.check()?;
            let (file, dir) = SceneFile::read(path)?;
            file.check_memory(&MemoryBudget::default())?;
            let shapes = Shapes::of(&file, dir)?;
            let mut report = BuildReport::default();
            for i in shard.range(shapes.assets.len()) {
                shapes.field(i, Some(&mut *store), &options.field, &mut report)?;
            }
            Ok(report)
        };
        build().map_err(|e: Error| e.in_file(path))
    }

    /// Reads a JSON scene file ([`SceneFile`]) and builds it.
    pub fn load(path: &Path, options: &DynamicOptions) -> Result<Self> {
        Self::load_with(path, options, None)
    }

    /// [`load`](Self::load), with the fields of [`build_with`](Self::build_with).
    ///
    /// ```
    /// use haarshift_relight::dynamic::{DynamicOptions, DynamicScene};
    /// use haarshift_relight::dynamic::fields::file::FieldStore;
    /// use haarshift::faces::{ParamKind, Parameterization};
    /// let dir = tempfile::tempdir().unwrap();
    /// let scene = dir.path().join("ball.json");
    /// std::fs::write(&scene, r#"{"objects": [{"generator": {"sphere": {"cells": 2}}}]}"#).unwrap();
    /// let mut options = DynamicOptions::new(Parameterization::new(ParamKind::LatLong, 4).unwrap());
    /// (options.field.circles, options.field.circle_points) = (3, 6);
    /// (options.field.shells, options.field.shell_grid) = (2, 2);
    /// let mut store = FieldStore::new(dir.path(), false);
    /// DynamicScene::load_with(&scene, &options, Some(&mut store)).unwrap();
    /// assert!(dir.path().join("sphere-cells-2.hsf").exists());
    /// ```
    pub fn load_with(
        path: &Path,
        options: &DynamicOptions,
        store: Option<&mut FieldStore>,
    ) -> Result<Self> {
        let (file, dir) = SceneFile::read(path)?;
        Self::build_with(&file, dir, options, store).map_err(|e| e.in_file(path))
    }

    /// Builds the scene of `file` (paths relative to `dir`): every shape's fields and every
    /// vertex's own transport.
    pub fn build(file: &SceneFile, dir: &Path, options: &DynamicOptions) -> Result<Self> {
        Self::build_with(file, dir, options, None)
    }

    /// [`build`](Self::build), with every shape's fields read from `store` when its file
    /// there matches, else built and written to it ([`FieldStore::field`]).
    ///
    /// ```
    /// use haarshift_relight::dynamic::{DynamicOptions, DynamicScene};
    /// use haarshift_relight::dynamic::fields::file::FieldStore;
    /// use haarshift_relight::SceneFile;
    /// use haarshift::faces::{ParamKind, Parameterization};
    /// let file: SceneFile = serde_json::from_str(
    ///     r#"{"objects": [{"generator": {"sphere": {"cells": 2}}}]}"#).unwrap();
    /// let mut options = DynamicOptions::new(Parameterization::new(ParamKind::LatLong, 4).unwrap());
    /// (options.field.circles, options.field.circle_points) = (3, 6);
    /// (options.field.shells, options.field.shell_grid) = (2, 2);
    /// let dir = tempfile::tempdir().unwrap();
    /// let mut store = FieldStore::new(dir.path(), false);
    /// let here = std::path::Path::new(".");
    /// let first = DynamicScene::build_with(&file, here, &options, Some(&mut store)).unwrap();
    /// assert_eq!((first.report().fields_written, first.report().fields_loaded), (1, 0));
    /// let second = DynamicScene::build_with(&file, here, &options, Some(&mut store)).unwrap();
    /// assert_eq!((second.report().fields_loaded, second.report().field_rays), (1, 0));
    /// assert_eq!(second.field(0), first.field(0));
    /// ```
    pub fn build_with(
        file: &SceneFile,
        dir: &Path,
        options: &DynamicOptions,
        mut store: Option<&mut FieldStore>,
    ) -> Result<Self> {
        options.check()?;
        file.check_memory(&MemoryBudget::default())?;
        if file.objects.is_empty() {
            return Err(SceneError::SceneFile("a scene needs at least one object".into()).into());
        }
        let param = options.param();
        let mut report = BuildReport::default();
        let shapes = Shapes::of(file, dir)?;
        let mut placed = Vec::new();
        let mut names: Vec<Option<String>> = Vec::new();
        for (k, object) in file.objects.iter().enumerate() {
            if let Some(name) = &object.name
                && names.iter().flatten().any(|n| n == name)
            {
                return Err(
                    SceneError::SceneFile(format!("two objects are named {name:?}")).into(),
                );
            }
            names.push(object.name.clone());
            let shape = shapes.of_object[k];
            let placement =
                Placement::from_transform(&object.transform, param).map_err(|e| match e {
                    Error::Scene { source, .. } => {
                        SceneError::SceneFile(format!("object {k}: {source}")).into()
                    }
                    other => other,
                })?;
            let brdf = object.material.brdf().map_err(|e| match e {
                Error::Scene { source, .. } => {
                    SceneError::SceneFile(format!("object {k}: {source}")).into()
                }
                other => other,
            })?;
            placed.push((
                shape,
                placement,
                object.albedo(&shapes.assets[shape])?,
                brdf,
            ));
        }
        // Validated before any field is built (relight::validate).
        if let Some(camera) = &file.camera {
            camera.check()?;
        }
        let meshes = placed
            .iter()
            .map(|(shape, p, _, _)| place_mesh(&shapes.assets[*shape].mesh, p, param))
            .collect::<Result<Vec<Mesh>>>()?;
        let objects_mesh = merge(meshes.iter().cloned());
        let ground = file
            .ground_cells()?
            .map(|cells| ground_plane_under(&objects_mesh.bounds(), cells))
            .transpose()?;
        let fields = (0..shapes.assets.len())
            .map(|i| {
                let field = shapes.field(i, store.as_deref_mut(), &options.field, &mut report)?;
                Ok(Arc::new(field))
            })
            .collect::<Result<Vec<_>>>()?;
        let visibility = VisibilityOptions {
            keep: options.keep_visibility,
            progress: options.progress,
            ..VisibilityOptions::new(param)
        };
        let own = |mesh: &Mesh, vertices: usize, report: &mut BuildReport| -> Result<_> {
            let (set, r) = vertex_major(mesh, &SceneBvh::new(mesh), &visibility)?;
            report.transport_rays += r.rays;
            report.transport_seconds += r.seconds;
            let rows: SparseRows<f32> = (0..vertices).map(|v| set.coefficients(v)).collect();
            Ok(Arc::new(rows))
        };
        let mut objects = Vec::with_capacity(placed.len());
        for (k, ((shape, placement, albedo, brdf), mesh)) in
            placed.into_iter().zip(&meshes).enumerate()
        {
            let mut with_ground = mesh.clone();
            if let Some(g) = &ground {
                with_ground.append(g);
            }
            let transport = own(&with_ground, mesh.vertex_count(), &mut report)?;
            objects.push(Object {
                name: names[k].clone(),
                shape,
                rest: placement,
                placement,
                albedo,
                brdf,
                orientation: None,
                transport,
                field: turned(&fields[shape], placement.turn)?,
            });
        }
        let ground = match ground {
            Some(g) => {
                let rows = own(&g, g.vertex_count(), &mut report)?;
                Some((g, rows))
            }
            None => None,
        };
        let all = merge(std::iter::once(objects_mesh).chain(ground.iter().map(|g| g.0.clone())));
        let mut scene = DynamicScene {
            options: *options,
            lift: ray_offset(&all),
            shapes: shapes.assets.into_iter().map(|a| a.mesh).collect(),
            fields,
            objects,
            ground,
            environment: file.environment.clone().map(|mut e| {
                e.path = dir.join(&e.path);
                e
            }),
            eye: file.camera.as_ref().map(|c| c.position),
            camera: file.camera.clone(),
            glossy: GlossyOptions::default(),
            report,
        };
        scene.orient()?;
        Ok(scene)
    }
}

/// A scene file's distinct shapes: objects with the same mesh file or generator share one.
struct Shapes {
    /// Each shape's mesh and the colour its file carries, in order of first use.
    assets: Vec<MeshAsset>,
    /// Where each came from: the mesh file or the generator.
    sources: Vec<(Option<PathBuf>, Option<Generator>)>,
    /// Each object's shape.
    of_object: Vec<usize>,
}

impl Shapes {
    /// The shapes of `file`, mesh paths relative to `dir`.
    fn of(file: &SceneFile, dir: &Path) -> Result<Self> {
        let mut shapes = Shapes {
            assets: Vec::new(),
            sources: Vec::new(),
            of_object: Vec::with_capacity(file.objects.len()),
        };
        for (k, object) in file.objects.iter().enumerate() {
            let source = (object.mesh.clone(), object.generator.clone());
            let shape = match shapes.sources.iter().position(|s| *s == source) {
                Some(i) => i,
                None => {
                    shapes
                        .assets
                        .push(object.asset(dir, k, &MemoryBudget::default())?);
                    shapes.sources.push(source);
                    shapes.assets.len() - 1
                }
            };
            shapes.of_object.push(shape);
        }
        Ok(shapes)
    }

    /// Shape `i`'s occlusion field: read from or built into `store` when there is one, else
    /// built; `report` counts what it cost.
    fn field(
        &self,
        i: usize,
        store: Option<&mut FieldStore>,
        options: &FieldOptions,
        report: &mut BuildReport,
    ) -> Result<OcclusionField> {
        let mesh = &self.assets[i].mesh;
        let (path, generator) = &self.sources[i];
        let stored = store.is_some();
        let (field, origin) = match store {
            Some(store) => store.field(mesh, path.as_deref(), generator.as_ref(), options)?,
            None => {
                let (field, r) = OcclusionField::build(mesh, options)?;
                let built = FieldOrigin::Built {
                    report: r,
                    bytes: 0,
                };
                (field, built)
            }
        };
        match origin {
            FieldOrigin::Built { report: r, bytes } => {
                report.field_rays += r.rays;
                report.field_seconds += r.seconds;
                // Nothing is written without a store.
                report.fields_written += usize::from(stored);
                report.field_file_bytes += bytes;
            }
            FieldOrigin::Loaded { bytes, seconds } => {
                report.fields_loaded += 1;
                report.field_file_bytes += bytes;
                report.field_load_seconds += seconds;
            }
        }
        report.field_bytes += field.stored_bytes();
        Ok(field)
    }
}
