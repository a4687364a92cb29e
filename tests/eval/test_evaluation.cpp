// Hand-computed expectations for ScanNet-style AP, PQ, super-point IoU_LS and semantic mIoU.
#include <cmath>
#include <map>
#include <vector>

#include <gtest/gtest.h>

#include "panmap/core/error.h"
#include "panmap/eval/evaluation.h"

namespace panmap {
namespace {

/// A scene built vertex range by vertex range: GT labels and transferred predicted labels.
struct Scene {
  LabelledMesh gt;
  TransferredLabels pred;

  /// Appends `count` vertices with the given GT and predicted labels (10 cm apart on x).
  void add(int count, int32_t gt_class, int32_t gt_instance, int32_t pred_class,
           int32_t pred_instance, int32_t superpoint = 0) {
    for (int i = 0; i < count; ++i) {
      gt.vertices.emplace_back(0.1f * static_cast<float>(gt.vertices.size()), 0.0f, 0.0f);
      gt.semantic.push_back(gt_class);
      gt.instance.push_back(gt_instance);
      pred.semantic.push_back(pred_class);
      pred.instance.push_back(pred_instance);
      pred.superpoint.push_back(superpoint);
    }
    pred.num_transferred = gt.vertices.size();
  }
};

const ClassMetrics& classOf(const EvalResult& r, int32_t c) {
  for (const ClassMetrics& m : r.classes) {
    if (m.class_id == c) return m;
  }
  throw Error("no class " + std::to_string(c));
}

TEST(EvalAp, ThresholdsAreNumpyArange) {
  const std::vector<double> t = scanNetApThresholds();
  ASSERT_EQ(t.size(), 9u);
  EXPECT_DOUBLE_EQ(t.front(), 0.5);
  EXPECT_DOUBLE_EQ(t[5], 0.75);
  EXPECT_NEAR(t.back(), 0.9, 1e-12);
}

TEST(EvalAp, PerfectPredictionScoresOne) {
  // Two chairs (class 5) and a table (class 7), a wall (stuff, void) and unlabelled vertices.
  LabelledMesh gt;
  const auto add = [&](int count, int32_t c, int32_t inst, int32_t sp) {
    for (int i = 0; i < count; ++i) {
      gt.vertices.emplace_back(0.1f * static_cast<float>(gt.vertices.size()), 0.0f, 0.0f);
      gt.semantic.push_back(c);
      gt.instance.push_back(inst);
      gt.superpoint.push_back(sp);
    }
  };
  add(150, 5, 1, 11);
  add(120, 5, 2, 12);
  add(200, 7, 3, 13);
  add(60, 1, 0, 14);
  add(30, 0, 0, 0);
  const EvalResult r = evaluate(gt, gt);  // prediction = GT, confidence 1
  EXPECT_EQ(r.num_transferred, gt.numVertices());
  EXPECT_DOUBLE_EQ(r.map, 1.0);
  EXPECT_DOUBLE_EQ(r.map25, 1.0);
  EXPECT_DOUBLE_EQ(r.map50, 1.0);
  EXPECT_DOUBLE_EQ(r.map75, 1.0);
  EXPECT_EQ(r.ntp50, 3);
  EXPECT_EQ(r.ntp75, 3);
  EXPECT_DOUBLE_EQ(r.pq50, 1.0);
  EXPECT_DOUBLE_EQ(r.pq75, 1.0);
  EXPECT_DOUBLE_EQ(r.sq50, 1.0);
  EXPECT_DOUBLE_EQ(r.rq75, 1.0);
  EXPECT_DOUBLE_EQ(r.iou_ls, 1.0);
  EXPECT_DOUBLE_EQ(r.iou_ls_instances, 1.0);
  EXPECT_DOUBLE_EQ(r.miou, 1.0);
  EXPECT_EQ(classOf(r, 5).num_gt, 2);
  EXPECT_EQ(classOf(r, 5).num_pred, 2);
  EXPECT_TRUE(std::isnan(classOf(r, 3).ap50));  // no GT of class 3: NaN, left out of means
  EXPECT_TRUE(std::isnan(classOf(r, 3).pq50));
  EXPECT_FALSE(formatEvalTable(r).empty());
}

// GT cabinet A (200 vertices) predicted as two halves of 100; cabinet B (150) predicted
// exactly. Halves have IoU 100/200 = 0.5, not > 0.5 (the script's strict test): no match.
// At 0.5 and 0.75: y = [TP(B) 1, FP 1, FP 1], hard FN 1 -> one curve point p = 1/3, r = 1/2
// plus (r 0, p 1); steps 0.5 * (0.5 - 0) twice -> AP = 1/3 * 1/4 + 1 * 1/4 = 1/3.
// PQ = 1 / (1 + 2/2 + 1/2) = 0.4. At 0.25 both halves match A: the first is the TP, the
// second a duplicate FP -> p = 2/3, r = 1 -> AP = 2/3 * 1/2 + 1/2 = 5/6.
TEST(EvalAp, HalfSplitIsNoMatchAtOneHalf) {
  Scene s;
  s.add(100, 3, 1, 3, 21);
  s.add(100, 3, 1, 3, 22);
  s.add(150, 3, 2, 3, 23);
  const EvalResult r = evaluateTransferred(s.gt, s.pred, {});
  const ClassMetrics& c = classOf(r, 3);
  EXPECT_EQ(c.num_gt, 2);
  EXPECT_EQ(c.num_pred, 3);
  EXPECT_NEAR(c.ap50, 1.0 / 3.0, 1e-12);
  EXPECT_NEAR(c.ap75, 1.0 / 3.0, 1e-12);
  EXPECT_NEAR(c.ap, 1.0 / 3.0, 1e-12);
  EXPECT_NEAR(c.ap25, 5.0 / 6.0, 1e-12);
  EXPECT_EQ(c.tp50, 1);
  EXPECT_EQ(c.tp75, 1);
  EXPECT_NEAR(c.pq50, 0.4, 1e-12);
  EXPECT_NEAR(c.sq50, 1.0, 1e-12);
  EXPECT_NEAR(c.rq50, 0.4, 1e-12);
  EXPECT_NEAR(r.map, 1.0 / 3.0, 1e-12);  // the only class with GT
  EXPECT_EQ(r.ntp50, 1);
}

// Unequal split 200 + 100 of a 300-vertex GT: IoU 2/3 matches at 0.5 but not at 0.75.
// 0.5: y = [TP 1, FP 1] -> p = 1/2, r = 1 -> AP = 1/2 * 1/2 + 1/2 = 3/4; PQ = (2/3) / 1.5.
// 0.75: y = [FP, FP], FN 1 -> AP 0, PQ 0.
TEST(EvalPq, UnequalSplit) {
  Scene s;
  s.add(200, 3, 1, 3, 21);
  s.add(100, 3, 1, 3, 22);
  const ClassMetrics c = classOf(evaluateTransferred(s.gt, s.pred, {}), 3);
  EXPECT_NEAR(c.ap50, 0.75, 1e-12);
  EXPECT_NEAR(c.ap75, 0.0, 1e-12);
  EXPECT_NEAR(c.pq50, (2.0 / 3.0) / 1.5, 1e-12);
  EXPECT_NEAR(c.sq50, 2.0 / 3.0, 1e-12);
  EXPECT_NEAR(c.pq75, 0.0, 1e-12);
  EXPECT_TRUE(std::isnan(c.sq75));
}

// One cabinet (100 vertices) found by prediction 1 (confidence 0.9); prediction 2 labels a
// chair's 100 vertices as cabinet (a false positive on non-void GT).
// FP below (0.5): points (p 1/2, r 1), (p 1, r 1), (p 1, r 0): steps 0, 1/2, 1/2 -> AP 1.
// FP above (0.95): points (p 1/2, r 1), (p 0, r 0), (p 1, r 0): steps 1/2, 1/2, 0 -> AP 1/4.
TEST(EvalAp, FalsePositiveRankChangesAp) {
  Scene s;
  s.add(100, 3, 1, 3, 1);
  s.add(100, 5, 2, 3, 2);
  const auto ap50 = [&](double fp_confidence, bool paper) {
    EvalConfig config;
    config.paper_compatible = paper;
    const EvalResult r = evaluateTransferred(s.gt, s.pred, {{1, 0.9}, {2, fp_confidence}}, config);
    EXPECT_EQ(r.paper_compatible, paper);
    return classOf(r, 3).ap50;
  };
  EXPECT_NEAR(ap50(0.5, false), 1.0, 1e-12);
  EXPECT_NEAR(ap50(0.95, false), 0.25, 1e-12);
  EXPECT_NEAR(ap50(0.95, false) - ap50(0.5, false), -0.75, 1e-12);
  // Paper-compatible: the matched prediction scores 1 and ranks above the FP again.
  EXPECT_NEAR(ap50(0.95, true), 1.0, 1e-12);
}

// A false prediction lying on void GT (unlabelled vertices) is not held against the method.
TEST(EvalAp, PredictionOnVoidIsIgnored) {
  Scene s;
  s.add(100, 3, 1, 3, 1);
  s.add(100, 0, 0, 3, 2);
  const EvalResult r = evaluateTransferred(s.gt, s.pred, {{1, 0.5}, {2, 0.9}});
  EXPECT_NEAR(classOf(r, 3).ap50, 1.0, 1e-12);
  EXPECT_NEAR(classOf(r, 3).pq50, 1.0, 1e-12);
}

// GT instances under 100 vertices are no targets; predictions under 100 vertices are skipped.
TEST(EvalAp, SmallInstancesAreIgnored) {
  Scene s;
  s.add(99, 3, 1, 3, 1);   // small cabinet, predicted exactly
  s.add(100, 3, 2, 3, 2);  // cabinet at the limit, predicted exactly
  s.add(99, 4, 3, 4, 3);   // small bed: class 4 has no GT instance
  const EvalResult r = evaluateTransferred(s.gt, s.pred, {});
  EXPECT_EQ(classOf(r, 3).num_gt, 1);
  EXPECT_EQ(classOf(r, 3).num_pred, 1);
  EXPECT_DOUBLE_EQ(classOf(r, 3).ap50, 1.0);
  EXPECT_EQ(classOf(r, 4).num_gt, 0);
  EXPECT_TRUE(std::isnan(classOf(r, 4).ap50));
  EXPECT_EQ(r.ntp50, 1);
  EXPECT_DOUBLE_EQ(r.map50, 1.0);

  // A 120-vertex prediction covering the small cabinet and 21 void vertices: IoU 99/120 > 0.5
  // with an ignored instance -> neither TP nor FP.
  Scene t;
  t.add(99, 3, 1, 3, 1);
  t.add(21, 0, 0, 3, 1);
  t.add(100, 3, 2, 3, 2);
  EXPECT_DOUBLE_EQ(classOf(evaluateTransferred(t.gt, t.pred, {}), 3).ap50, 1.0);
}

// Cabinet o of 200 vertices; super-point 1 = 100 of its vertices; super-point 2 = its other
// 100 plus 50 void vertices (2/3 inside); super-point 3 lies on void only.
// IoU(1, o) = 100/200, IoU(2, o) = 100/(200 + 150 - 100) -> IoU_LS 0.9; best single 0.5.
TEST(EvalSuperpoint, IoULsSumsMostlyInsideSuperpoints) {
  Scene s;
  s.add(100, 3, 1, 3, 1, 1);
  s.add(100, 3, 1, 3, 1, 2);
  s.add(50, 0, 0, 0, 0, 2);
  s.add(40, 0, 0, 0, 0, 3);
  const EvalResult r = evaluateTransferred(s.gt, s.pred, {});
  EXPECT_NEAR(classOf(r, 3).iou_ls, 0.9, 1e-12);
  EXPECT_NEAR(classOf(r, 3).iou_ls_best, 0.5, 1e-12);
  EXPECT_NEAR(r.iou_ls, 0.9, 1e-12);
  EXPECT_NEAR(r.iou_ls_instances, 0.9, 1e-12);

  // A super-point with only a third of its vertices inside o does not count.
  Scene t;
  t.add(100, 3, 1, 3, 1, 1);
  t.add(100, 3, 1, 3, 1, 2);
  t.add(200, 0, 0, 0, 0, 2);
  EXPECT_NEAR(evaluateTransferred(t.gt, t.pred, {}).iou_ls, 0.5, 1e-12);
}

// GT [cabinet, cabinet, bed, unlabelled], predicted [cabinet, bed, bed, cabinet]:
// cabinet 1 / (1 + 0 + 1) = 1/2 (the unlabelled vertex is ignored), bed 1 / (1 + 1) = 1/2.
TEST(EvalSemantic, MeanIoUIgnoresUnevaluatedGt) {
  Scene s;
  s.add(1, 3, 0, 3, 0);
  s.add(1, 3, 0, 4, 0);
  s.add(1, 4, 0, 4, 0);
  s.add(1, 0, 0, 3, 0);
  const EvalResult r = evaluateTransferred(s.gt, s.pred, {});
  EXPECT_NEAR(classOf(r, 3).semantic_iou, 0.5, 1e-12);
  EXPECT_NEAR(classOf(r, 4).semantic_iou, 0.5, 1e-12);
  EXPECT_NEAR(r.miou, 0.5, 1e-12);
  EXPECT_TRUE(std::isnan(r.map));
}

// GT [cabinet x4, bed x4], predicted [cabinet x3 + chair, bed x4]: cabinet 3/4, bed 1, chair (no
// GT vertex) 0. ScanNet's per-scene mean counts the chair: (3/4 + 1 + 0) / 3 = 7/12; over the
// GT's classes it is (3/4 + 1) / 2 = 7/8, the chair counted apart as 1 spurious class on 1
// vertex (its vertex still costs the cabinet).
TEST(EvalSemantic, SpuriousClassesAreCountedApartFromTheMeanOverGtClasses) {
  Scene s;
  s.add(3, 3, 0, 3, 0);
  s.add(1, 3, 0, 5, 0);
  s.add(4, 4, 0, 4, 0);
  const EvalResult r = evaluateTransferred(s.gt, s.pred, {});
  EXPECT_NEAR(classOf(r, 3).semantic_iou, 0.75, 1e-12);
  EXPECT_EQ(classOf(r, 3).semantic_gt_vertices, 4);
  EXPECT_EQ(classOf(r, 3).semantic_false_vertices, 0);
  EXPECT_NEAR(classOf(r, 5).semantic_iou, 0.0, 1e-12);
  EXPECT_EQ(classOf(r, 5).semantic_gt_vertices, 0);
  EXPECT_EQ(classOf(r, 5).semantic_false_vertices, 1);
  EXPECT_NEAR(r.miou, 7.0 / 12.0, 1e-12);
  EXPECT_NEAR(r.miou_gt_classes, 7.0 / 8.0, 1e-12);
  EXPECT_EQ(r.spurious_classes, 1);
  EXPECT_EQ(r.spurious_vertices, 1);

  // Without the stray vertex there is nothing spurious and both means agree.
  Scene t;
  t.add(4, 3, 0, 3, 0);
  t.add(4, 4, 0, 4, 0);
  const EvalResult clean = evaluateTransferred(t.gt, t.pred, {});
  EXPECT_DOUBLE_EQ(clean.miou, 1.0);
  EXPECT_DOUBLE_EQ(clean.miou_gt_classes, 1.0);
  EXPECT_EQ(clean.spurious_classes, 0);
  EXPECT_EQ(clean.spurious_vertices, 0);
}

TEST(EvalAp, RejectsMismatchedLengths) {
  Scene s;
  s.add(3, 3, 1, 3, 1);
  s.pred.instance.pop_back();
  EXPECT_THROW(evaluateTransferred(s.gt, s.pred, {}), Error);
}

}  // namespace
}  // namespace panmap
