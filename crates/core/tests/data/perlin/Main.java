// Prints ImprovedNoise.noise at 80 deterministic points as "x y z value",
// every double in full precision (Java's shortest round-trip repr).
// Build and run:  javac -d /tmp/perlin ImprovedNoise.java Main.java
//                 java -cp /tmp/perlin Main > reference_points.txt
public final class Main {
   public static void main(String[] args) {
      double[][] fixed = {
         {3.14, 42, 7},          // Perlin's published check value
         {0, 0, 0},
         {0.5, 0.5, 0.5},
         {1.5, 2.25, 3.75},
         {-0.5, -0.25, -0.75},
         {-1.5, 2.5, -3.5},
         {0.1, 0.2, 0.3},
         {-0.1, -0.2, -0.3},
         {100, 100, 100},
         {-100, -100, -100},
         {99.99, -99.99, 0.01},
         {-63.7, 12.3, 88.8},
         {255.5, 256.5, 257.5},  // wrap of the permutation index
         {-255.5, -256.5, -257.5},
         {12.345, -67.891, 23.456},
         {0.999999, 1.000001, -0.000001},
      };
      java.util.ArrayList<double[]> pts = new java.util.ArrayList<>();
      for (double[] q : fixed) pts.add(q);
      // 48 more from a fixed 64-bit LCG (Knuth's MMIX constants), mixing
      // small (|c| < 2), medium (|c| < 10) and large (|c| < 100) ranges.
      long s = 0x2002L;
      double[] scales = {2.0, 10.0, 100.0};
      for (int i = 0; pts.size() < 64; i++) {
         double[] q = new double[3];
         for (int k = 0; k < 3; k++) {
            s = s * 6364136223846793005L + 1442695040888963407L;
            double r = (double)(s >>> 11) / (double)(1L << 53);  // [0, 1)
            q[k] = (2.0 * r - 1.0) * scales[i % 3];
         }
         pts.add(q);
      }
      // 16 far from the origin (|c| < 1e3 and < 1e4), where single
      // precision has lost the noise's digits: a reference must not.
      double[] far = {1000.0, 10000.0};
      for (int i = 0; pts.size() < 80; i++) {
         double[] q = new double[3];
         for (int k = 0; k < 3; k++) {
            s = s * 6364136223846793005L + 1442695040888963407L;
            double r = (double)(s >>> 11) / (double)(1L << 53);  // [0, 1)
            q[k] = (2.0 * r - 1.0) * far[i % 2];
         }
         pts.add(q);
      }
      StringBuilder sb = new StringBuilder();
      for (double[] q : pts) {
         double n = ImprovedNoise.noise(q[0], q[1], q[2]);
         sb.append(Double.toString(q[0])).append(' ')
           .append(Double.toString(q[1])).append(' ')
           .append(Double.toString(q[2])).append(' ')
           .append(Double.toString(n)).append('\n');
      }
      System.out.print(sb);
   }
}
