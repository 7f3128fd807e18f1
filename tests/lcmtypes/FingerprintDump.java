// For each class named on the command line prints "<class> <LCM_FINGERPRINT as hex> <resolved>", where
// <resolved> is the class lcm-spy's own type database (lcm.spy.LCMTypeDatabase, which scans the class
// path like lcm-spy does) finds for that fingerprint, or "none".
public class FingerprintDump {
  public static void main(String[] args) throws Exception {
    lcm.spy.LCMTypeDatabase spy = new lcm.spy.LCMTypeDatabase();
    for (String name : args) {
      long fp = Class.forName(name).getField("LCM_FINGERPRINT").getLong(null);
      Class<?> resolved = spy.getClassByFingerprint(fp);
      System.out.println(name + " " + Long.toHexString(fp) + " "
                         + (resolved == null ? "none" : resolved.getName()));
    }
  }
}
